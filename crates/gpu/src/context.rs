//! Choosing an adapter and opening a device on it.
//!
//! Preference: a hardware GPU (discrete, then integrated, then virtual), then Mesa's
//! software adapters (lavapipe on Vulkan, llvmpipe on GL); within a kind, Vulkan, Metal and
//! DX12 before GL. `WGPU_BACKEND` restricts the backends, a name restricts the adapters.

use std::sync::Arc;

use wgpu::{Adapter, AdapterInfo, Backend, DeviceType};

use pathlight_core::RenderError;

/// An open device with its queue and the adapter it runs on (clones share the device).
#[derive(Debug, Clone)]
pub struct GpuContext {
    /// The device.
    pub device: wgpu::Device,
    /// Its queue.
    pub queue: wgpu::Queue,
    /// The adapter.
    pub adapter: Adapter,
    /// The adapter's description.
    pub adapter_info: AdapterInfo,
}

/// How hardware-like an adapter is; lower is preferred.
fn rank(info: &AdapterInfo) -> (u8, u8) {
    let kind = match info.device_type {
        DeviceType::DiscreteGpu => 0,
        DeviceType::IntegratedGpu => 1,
        DeviceType::VirtualGpu => 2,
        DeviceType::Cpu => 3,
        DeviceType::Other => 4,
    };
    let backend = match info.backend {
        Backend::Vulkan | Backend::Metal | Backend::Dx12 => 0,
        _ => 1,
    };
    (kind, backend)
}

/// Whether an adapter is a hardware GPU (discrete, integrated, virtual, or a kind its driver
/// does not name) rather than a software rasteriser (`DeviceType::Cpu`: lavapipe, llvmpipe,
/// SwiftShader, WARP), which runs the WGSL far slower than the native CPU backend.
pub fn is_hardware(info: &AdapterInfo) -> bool {
    info.device_type != DeviceType::Cpu
}

/// What `--backend auto` runs on, given the adapters found.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum AutoChoice {
    /// The WGSL on the hardware GPU at this index: the best-ranked one.
    Gpu(usize),
    /// The native CPU backend, as there is no hardware GPU; the index is the software
    /// adapter `--backend gpu` would run on, if there is one.
    Cpu(Option<usize>),
}

/// The `--backend auto` choice among `adapters`: the best hardware GPU, else the CPU
/// backend.
pub fn auto_choice(adapters: &[AdapterInfo]) -> AutoChoice {
    let best = |hardware: bool| {
        (0..adapters.len())
            .filter(|&i| is_hardware(&adapters[i]) == hardware)
            .min_by_key(|&i| rank(&adapters[i]))
    };
    match best(true) {
        Some(gpu) => AutoChoice::Gpu(gpu),
        None => AutoChoice::Cpu(best(false)),
    }
}

/// One line naming an adapter, as printed by the CLI.
pub fn describe(info: &AdapterInfo) -> String {
    format!(
        "{} ({:?}, {:?}, driver {} {})",
        info.name, info.backend, info.device_type, info.driver, info.driver_info
    )
}

/// The adapters on the backends named by `WGPU_BACKEND`; without it, those on the native
/// backends (Vulkan, Metal, DX12), or the GL ones when there are none.
pub fn available_adapters() -> Vec<Adapter> {
    if let Some(backends) = wgpu::Backends::from_env() {
        return adapters_on(backends);
    }
    let native = adapters_on(wgpu::Backends::PRIMARY);
    if !native.is_empty() {
        return native;
    }
    adapters_on(wgpu::Backends::GL)
}

/// wgpu's check of indirect dispatches' arguments, left out: it adds a dispatch and barriers
/// before each indirect one, and the only indirect dispatches, the wavefront's
/// (`wavefront.rs`), bound their arguments themselves.
const UNCHECKED_INDIRECT: wgpu::InstanceFlags = wgpu::InstanceFlags::VALIDATION_INDIRECT_CALL;

/// Adapters on `backends`, from an instance that initialises only those backends.
fn adapters_on(backends: wgpu::Backends) -> Vec<Adapter> {
    let mut descriptor = wgpu::InstanceDescriptor::new_without_display_handle_from_env();
    descriptor.backends = backends;
    descriptor.flags.remove(UNCHECKED_INDIRECT);
    let instance = wgpu::Instance::new(descriptor);
    pollster::block_on(instance.enumerate_adapters(backends))
}

/// The best-ranked adapter of `adapters` whose name contains `name` (any case), or whose
/// backend is called `name`.
fn choose(adapters: Vec<Adapter>, name: Option<&str>) -> Result<Adapter, RenderError> {
    let names: Vec<String> = adapters.iter().map(|a| describe(&a.get_info())).collect();
    let wanted = name.map(str::to_lowercase);
    adapters
        .into_iter()
        .filter(|a| {
            let info = a.get_info();
            wanted.as_ref().is_none_or(|w| {
                info.name.to_lowercase().contains(w)
                    || format!("{:?}", info.backend).to_lowercase() == *w
            })
        })
        .min_by_key(|a| rank(&a.get_info()))
        .ok_or_else(|| match name {
            Some(name) => RenderError::NoAdapter(format!(
                "no adapter matches {name:?}; found: {}",
                if names.is_empty() {
                    "none".to_string()
                } else {
                    names.join("; ")
                }
            )),
            None => RenderError::NoAdapter(
                "no GPU adapter found. Install a Vulkan driver; without a GPU, Mesa's \
                 software one works: `apt-get install mesa-vulkan-drivers` (lavapipe), or \
                 a GL driver (`libgl1-mesa-dri`, llvmpipe)"
                    .into(),
            ),
        })
}

impl GpuContext {
    /// Opens the preferred adapter, or the best one whose name contains `name` (any case).
    pub fn new(name: Option<&str>) -> Result<Self, RenderError> {
        Self::from_adapter(&choose(available_adapters(), name)?)
    }

    /// Opens the preferred adapter (or the best matching `name`) among those that can
    /// present to `window`, with a surface on the window. Backends are searched as by
    /// [`available_adapters`].
    pub fn for_window<W>(
        name: Option<&str>,
        window: Arc<W>,
    ) -> Result<(Self, wgpu::Surface<'static>), RenderError>
    where
        W: wgpu::WindowHandle + wgpu::rwh::HasDisplayHandle + std::fmt::Debug + 'static,
    {
        let searches = match wgpu::Backends::from_env() {
            Some(backends) => vec![backends],
            None => vec![wgpu::Backends::PRIMARY, wgpu::Backends::GL],
        };
        let mut last_error = None;
        for backends in searches {
            let mut descriptor = wgpu::InstanceDescriptor::new_with_display_handle_from_env(
                Box::new(window.clone()),
            );
            descriptor.backends = backends;
            descriptor.flags.remove(UNCHECKED_INDIRECT);
            let instance = wgpu::Instance::new(descriptor);
            let surface = match instance.create_surface(window.clone()) {
                Ok(surface) => surface,
                Err(err) => {
                    last_error = Some(RenderError::NoAdapter(format!(
                        "cannot create a surface on the window ({backends:?}): {err}"
                    )));
                    continue;
                }
            };
            let adapters: Vec<Adapter> = pollster::block_on(instance.enumerate_adapters(backends))
                .into_iter()
                .filter(|a| a.is_surface_supported(&surface))
                .collect();
            if adapters.is_empty() {
                continue;
            }
            let ctx = Self::from_adapter(&choose(adapters, name)?)?;
            return Ok((ctx, surface));
        }
        Err(last_error.unwrap_or_else(|| {
            RenderError::NoAdapter(
                "no adapter can present to the window. Install a Vulkan driver (without a GPU: \
                 `apt-get install mesa-vulkan-drivers`), or render headless with `pathlight render`"
                    .into(),
            )
        }))
    }

    /// Opens a device on `adapter` with the adapter's own limits (more storage buffers and
    /// larger bindings than wgpu's defaults), and timestamp queries where it has them.
    pub fn from_adapter(adapter: &Adapter) -> Result<Self, RenderError> {
        let adapter_info = adapter.get_info();
        let descriptor = wgpu::DeviceDescriptor {
            label: Some("pathlight device"),
            required_features: adapter.features() & crate::dispatch_times::FEATURES,
            required_limits: adapter.limits(),
            ..Default::default()
        };
        let (device, queue) =
            pollster::block_on(adapter.request_device(&descriptor)).map_err(|err| {
                RenderError::Device {
                    adapter: adapter_info.name.clone(),
                    message: err.to_string(),
                }
            })?;
        Ok(Self {
            device,
            queue,
            adapter: adapter.clone(),
            adapter_info,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn adapter(device_type: DeviceType, backend: Backend) -> AdapterInfo {
        AdapterInfo::new(device_type, backend)
    }

    #[test]
    fn auto_takes_the_best_hardware_gpu_and_the_cpu_backend_over_software_ones() {
        let lavapipe = adapter(DeviceType::Cpu, Backend::Vulkan);
        let llvmpipe = adapter(DeviceType::Cpu, Backend::Gl);
        let integrated_gl = adapter(DeviceType::IntegratedGpu, Backend::Gl);
        let integrated = adapter(DeviceType::IntegratedGpu, Backend::Vulkan);
        let discrete = adapter(DeviceType::DiscreteGpu, Backend::Vulkan);
        let virtual_gpu = adapter(DeviceType::VirtualGpu, Backend::Vulkan);
        let unnamed = adapter(DeviceType::Other, Backend::Gl);

        // Hardware of any kind wins over software; among hardware, the usual ranking.
        let cases = [
            (
                vec![lavapipe.clone(), integrated_gl.clone(), integrated.clone()],
                AutoChoice::Gpu(2),
            ),
            (
                vec![integrated.clone(), lavapipe.clone(), discrete.clone()],
                AutoChoice::Gpu(2),
            ),
            (vec![lavapipe.clone(), virtual_gpu], AutoChoice::Gpu(1)),
            (vec![lavapipe.clone(), unnamed], AutoChoice::Gpu(1)),
            // Software only: the CPU backend, naming the adapter `--backend gpu` would take.
            (
                vec![llvmpipe.clone(), lavapipe.clone()],
                AutoChoice::Cpu(Some(1)),
            ),
            (vec![llvmpipe], AutoChoice::Cpu(Some(0))),
            // None at all.
            (vec![], AutoChoice::Cpu(None)),
        ];
        for (adapters, expected) in cases {
            let kinds: Vec<_> = adapters
                .iter()
                .map(|a| (a.device_type, a.backend))
                .collect();
            assert_eq!(auto_choice(&adapters), expected, "{kinds:?}");
        }
    }
}
