//! Prints what each Vulkan device's driver reports of the integrator kernels it compiles for a
//! scene (VK_KHR_pipeline_executable_properties): registers, spills, local memory, instruction
//! counts, as the driver names them. On a GPU the registers a thread needs decide how many
//! threads an SM keeps in flight, which hides the walk's memory latency.
//!
//! The kernel is the renderer's own ([`IntegratorKernel`]: the same WGSL, stack and
//! pipeline constants), translated to SPIR-V by naga as wgpu does, and compiled in a bare
//! Vulkan pipeline that asks the driver for its statistics.
//!
//!   cargo run --release -p pathlight-gpu --example kernel_stats -- [--all] [--wavefront] [SCENE]
//!
//! SCENE: a scene file (TOML or glTF); the built-in default scene when absent. `--all`
//! compiles every feature in (instances, glTF materials, textures, normal maps, alpha,
//! auxiliary images), as a scene that uses them all gets it. `--wavefront`: the wavefront's
//! kernels (`--gpu-kernel wavefront`), each entry point in turn, instead of the megakernel.

use std::ffi::CStr;
use std::path::Path;

use anyhow::{Context, Result, bail};
use ash::vk;
use naga::back::{PipelineConstants, spv};
use naga::valid::{Capabilities, ValidationFlags, Validator};
use pathlight_core::PreparedScene;
use pathlight_gpu::{Accel, IntegratorKernel, Kernel};
use pathlight_scene::{default_scene, load_scene_file};

fn main() -> Result<()> {
    let mut args: Vec<String> = std::env::args().skip(1).collect();
    let all = args.iter().any(|a| a == "--all");
    let wavefront = args.iter().any(|a| a == "--wavefront");
    args.retain(|a| !a.starts_with("--"));
    let scene = match args.first() {
        Some(path) => load_scene_file(Path::new(path))?,
        None => default_scene::load()?,
    };
    let split = if wavefront {
        Kernel::Wavefront
    } else {
        Kernel::Megakernel
    };
    let mut kernel = IntegratorKernel::of(
        &PreparedScene::new(&scene)?,
        &scene.settings,
        Accel::Bvh,
        split,
    )?;
    if all {
        for (name, value) in &mut kernel.constants {
            if *name != "ACCEL" {
                *value = 1.0;
            }
        }
    }
    println!("pipeline constants: {:?}", kernel.constants);
    for entry_point in kernel.entry_points {
        println!("\n== entry point {entry_point}");
        report_entry(&kernel, entry_point)?;
    }
    Ok(())
}

/// Compiles entry point `entry_point` of `kernel` on every Vulkan device and prints what each
/// driver reports.
fn report_entry(kernel: &IntegratorKernel, entry_point: &str) -> Result<()> {
    let (words, bindings) = spirv(kernel, entry_point)?;
    let entry_name = std::ffi::CString::new(entry_point)?;
    // SAFETY: the Vulkan loader is a system library; nothing else in this process uses it.
    let entry = unsafe { ash::Entry::load() }.context("no Vulkan loader")?;
    let app = vk::ApplicationInfo::default().api_version(vk::API_VERSION_1_2);
    // SAFETY: a plain instance with valid create info.
    let instance = unsafe {
        entry.create_instance(
            &vk::InstanceCreateInfo::default().application_info(&app),
            None,
        )
    }?;
    // SAFETY: `instance` is valid for the calls below and destroyed last.
    unsafe {
        for physical in instance.enumerate_physical_devices()? {
            let name = instance
                .get_physical_device_properties(physical)
                .device_name_as_c_str()?
                .to_owned();
            println!("\n{}", name.to_string_lossy());
            if let Err(err) = report(&instance, physical, &words, &bindings, &entry_name) {
                println!("  no statistics: {err:#}");
            }
        }
        instance.destroy_instance(None);
    }
    Ok(())
}

/// A storage buffer's (group, binding).
type Binding = (u32, u32);

/// The kernel's SPIR-V with its pipeline constants applied, and its storage buffers.
fn spirv(kernel: &IntegratorKernel, entry_point: &str) -> Result<(Vec<u32>, Vec<Binding>)> {
    let module = naga::front::wgsl::parse_str(&kernel.source)?;
    let info = Validator::new(ValidationFlags::all(), Capabilities::all()).validate(&module)?;
    let mut constants = PipelineConstants::default();
    for (name, value) in &kernel.constants {
        constants.insert((*name).to_owned(), *value);
    }
    let entry = (naga::ShaderStage::Compute, entry_point);
    let (module, info) =
        naga::back::pipeline_constants::process_overrides(&module, &info, Some(entry), &constants)?;
    let pipeline = spv::PipelineOptions {
        shader_stage: entry.0,
        entry_point: entry.1.to_owned(),
    };
    let words = spv::write_vec(&module, &info, &spv::Options::default(), Some(&pipeline))?;
    let bindings = module
        .global_variables
        .iter()
        .filter_map(|(_, var)| {
            let naga::AddressSpace::Storage { .. } = var.space else {
                return None;
            };
            let binding = var.binding.as_ref()?;
            Some((binding.group, binding.binding))
        })
        .collect();
    Ok((words, bindings))
}

/// Compiles the kernel on `physical` with statistics captured and prints them.
///
/// # Safety
/// `instance` and `physical` must be valid.
unsafe fn report(
    instance: &ash::Instance,
    physical: vk::PhysicalDevice,
    words: &[u32],
    bindings: &[Binding],
    name: &CStr,
) -> Result<()> {
    let extension = ash::khr::pipeline_executable_properties::NAME;
    // SAFETY: valid handles (the caller's contract); every object made here is destroyed
    // with the device before returning.
    unsafe {
        let supported = instance
            .enumerate_device_extension_properties(physical)?
            .iter()
            .any(|e| e.extension_name_as_c_str() == Ok(extension));
        if !supported {
            bail!("the driver lacks {}", extension.to_string_lossy());
        }
        let family = instance
            .get_physical_device_queue_family_properties(physical)
            .iter()
            .position(|f| f.queue_flags.contains(vk::QueueFlags::COMPUTE))
            .context("no compute queue")? as u32;
        let priorities = [1.0];
        let queues = [vk::DeviceQueueCreateInfo::default()
            .queue_family_index(family)
            .queue_priorities(&priorities)];
        let extensions = [extension.as_ptr()];
        let mut executable_info =
            vk::PhysicalDevicePipelineExecutablePropertiesFeaturesKHR::default()
                .pipeline_executable_info(true);
        let device = instance.create_device(
            physical,
            &vk::DeviceCreateInfo::default()
                .queue_create_infos(&queues)
                .enabled_extension_names(&extensions)
                .push_next(&mut executable_info),
            None,
        )?;
        let result = compile_and_print(instance, &device, words, bindings, name);
        device.destroy_device(None);
        result
    }
}

/// The pipeline's executables and their statistics, printed.
///
/// # Safety
/// `device` must be valid and have the pipeline-executable-properties extension enabled.
unsafe fn compile_and_print(
    instance: &ash::Instance,
    device: &ash::Device,
    words: &[u32],
    bindings: &[Binding],
    name: &CStr,
) -> Result<()> {
    // SAFETY: the caller's contract; every object made here is destroyed before returning.
    unsafe {
        let groups = bindings.iter().map(|b| b.0 + 1).max().unwrap_or(0);
        let mut set_layouts = Vec::new();
        for group in 0..groups {
            let entries: Vec<_> = bindings
                .iter()
                .filter(|b| b.0 == group)
                .map(|b| {
                    vk::DescriptorSetLayoutBinding::default()
                        .binding(b.1)
                        .descriptor_type(vk::DescriptorType::STORAGE_BUFFER)
                        .descriptor_count(1)
                        .stage_flags(vk::ShaderStageFlags::COMPUTE)
                })
                .collect();
            set_layouts.push(device.create_descriptor_set_layout(
                &vk::DescriptorSetLayoutCreateInfo::default().bindings(&entries),
                None,
            )?);
        }
        let layout = device.create_pipeline_layout(
            &vk::PipelineLayoutCreateInfo::default().set_layouts(&set_layouts),
            None,
        )?;
        let shader = device
            .create_shader_module(&vk::ShaderModuleCreateInfo::default().code(words), None)?;
        let stage = vk::PipelineShaderStageCreateInfo::default()
            .stage(vk::ShaderStageFlags::COMPUTE)
            .module(shader)
            .name(name);
        let create = vk::ComputePipelineCreateInfo::default()
            .stage(stage)
            .layout(layout)
            .flags(vk::PipelineCreateFlags::CAPTURE_STATISTICS_KHR);
        let pipeline = device
            .create_compute_pipelines(vk::PipelineCache::null(), &[create], None)
            .map_err(|(_, err)| err)?[0];
        let properties = ash::khr::pipeline_executable_properties::Device::new(instance, device);
        let executables = properties.get_pipeline_executable_properties(
            &vk::PipelineInfoKHR::default().pipeline(pipeline),
        )?;
        for (index, executable) in executables.iter().enumerate() {
            println!("  executable {index}: {}", text(executable.name_as_c_str()));
            let info = vk::PipelineExecutableInfoKHR::default()
                .pipeline(pipeline)
                .executable_index(index as u32);
            for statistic in properties.get_pipeline_executable_statistics(&info)? {
                let value = match statistic.format {
                    vk::PipelineExecutableStatisticFormatKHR::BOOL32 => {
                        format!("{}", statistic.value.b32 != 0)
                    }
                    vk::PipelineExecutableStatisticFormatKHR::INT64 => {
                        format!("{}", statistic.value.i64)
                    }
                    vk::PipelineExecutableStatisticFormatKHR::UINT64 => {
                        format!("{}", statistic.value.u64)
                    }
                    _ => format!("{}", statistic.value.f64),
                };
                println!("    {:<32} {value}", text(statistic.name_as_c_str()));
            }
        }
        device.destroy_pipeline(pipeline, None);
        device.destroy_shader_module(shader, None);
        device.destroy_pipeline_layout(layout, None);
        for set_layout in set_layouts {
            device.destroy_descriptor_set_layout(set_layout, None);
        }
    }
    Ok(())
}

/// A driver's fixed-size string, or a placeholder when it is not terminated.
fn text(name: Result<&CStr, std::ffi::FromBytesUntilNulError>) -> String {
    name.map_or_else(|_| "?".into(), |n| n.to_string_lossy().into_owned())
}
