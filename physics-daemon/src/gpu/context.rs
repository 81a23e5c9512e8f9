//! The daemon's one wgpu device and its compiled step and scan pipelines ([`Context`]),
//! created the first time a plane asks for the GPU and shared by every GPU plane after.

use std::sync::{Arc, OnceLock};

/// The shared wgpu device and the compiled step and scan pipelines.
pub struct Context {
    pub(crate) device: wgpu::Device,
    pub(crate) queue: wgpu::Queue,
    /// "NAME (BACKEND, TYPE)" of the adapter in use.
    pub adapter: String,
    pub(crate) step_layout: wgpu::BindGroupLayout,
    pub(crate) scan_layout: wgpu::BindGroupLayout,
    pub(crate) forces: wgpu::ComputePipeline,
    pub(crate) count: wgpu::ComputePipeline,
    pub(crate) scatter: wgpu::ComputePipeline,
    pub(crate) solve: wgpu::ComputePipeline,
    pub(crate) pairs: wgpu::ComputePipeline,
    pub(crate) scan_blocks: wgpu::ComputePipeline,
    pub(crate) add_sums: wgpu::ComputePipeline,
    /// Largest storage binding and buffer the device accepts (bytes).
    pub(crate) max_binding: u64,
}

static CONTEXT: OnceLock<Result<Arc<Context>, String>> = OnceLock::new();

/// The daemon's GPU context, created on first use. The error (no adapter, no device, a
/// pipeline that failed to build) is remembered: later calls return it without retrying.
pub fn context() -> Result<Arc<Context>, String> {
    CONTEXT.get_or_init(|| Context::new().map(Arc::new)).clone()
}

/// Name of the adapter when the context exists or can be made.
pub fn adapter_name() -> Result<String, String> {
    context().map(|c| c.adapter.clone())
}

fn storage(binding: u32, read_only: bool) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::COMPUTE,
        ty: wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Storage { read_only },
            has_dynamic_offset: false,
            min_binding_size: None,
        },
        count: None,
    }
}

fn uniform(binding: u32) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::COMPUTE,
        ty: wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Uniform,
            has_dynamic_offset: false,
            min_binding_size: None,
        },
        count: None,
    }
}

impl Context {
    fn new() -> Result<Context, String> {
        if std::env::var("PHYSICS_GPU").is_ok_and(|v| v == "off" || v == "0") {
            return Err(
                "no GPU adapter: PHYSICS_GPU=off in the daemon's environment hides \
                        every adapter"
                    .into(),
            );
        }
        let instance = wgpu::Instance::new(wgpu::InstanceDescriptor {
            backends: wgpu::Backends::PRIMARY,
            ..wgpu::InstanceDescriptor::new_without_display_handle()
        });
        let adapter = pollster::block_on(instance.request_adapter(&wgpu::RequestAdapterOptions {
            power_preference: wgpu::PowerPreference::HighPerformance,
            force_fallback_adapter: false,
            compatible_surface: None,
            ..Default::default()
        }))
        .map_err(|e| {
            format!(
                "no GPU adapter (Vulkan, Metal or DX12) was found: {e}; on Linux without a GPU \
                 install Mesa's lavapipe (Debian: mesa-vulkan-drivers libvulkan1)"
            )
        })?;
        let info = adapter.get_info();
        let name = format!("{} ({:?}, {:?})", info.name, info.backend, info.device_type);
        let limits = adapter.limits();
        let (device, queue) = pollster::block_on(adapter.request_device(&wgpu::DeviceDescriptor {
            label: Some("physics-gpu"),
            required_features: wgpu::Features::empty(),
            required_limits: limits.clone(),
            ..Default::default()
        }))
        .map_err(|e| format!("the GPU adapter {name} refused a device: {e}"))?;
        let scope = device.push_error_scope(wgpu::ErrorFilter::Validation);
        let step_module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("step.wgsl"),
            source: wgpu::ShaderSource::Wgsl(include_str!("shaders/step.wgsl").into()),
        });
        let scan_module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("scan.wgsl"),
            source: wgpu::ShaderSource::Wgsl(include_str!("shaders/scan.wgsl").into()),
        });
        let step_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("step"),
            entries: &[
                uniform(0),
                storage(1, true),
                storage(2, false),
                storage(3, true),
                storage(4, false),
                storage(5, false),
                storage(6, false),
                storage(7, false),
            ],
        });
        let scan_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("scan"),
            entries: &[storage(0, false), storage(1, false), uniform(2)],
        });
        let pipeline = |layout: &wgpu::BindGroupLayout, module: &wgpu::ShaderModule, entry| {
            let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                label: Some(entry),
                bind_group_layouts: &[Some(layout)],
                immediate_size: 0,
            });
            device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
                label: Some(entry),
                layout: Some(&layout),
                module,
                entry_point: Some(entry),
                compilation_options: Default::default(),
                cache: None,
            })
        };
        let context = Context {
            forces: pipeline(&step_layout, &step_module, "forces"),
            count: pipeline(&step_layout, &step_module, "count"),
            scatter: pipeline(&step_layout, &step_module, "scatter"),
            solve: pipeline(&step_layout, &step_module, "solve"),
            pairs: pipeline(&step_layout, &step_module, "pairs"),
            scan_blocks: pipeline(&scan_layout, &scan_module, "scan_blocks"),
            add_sums: pipeline(&scan_layout, &scan_module, "add_sums"),
            step_layout,
            scan_layout,
            max_binding: (limits.max_storage_buffer_binding_size as u64)
                .min(limits.max_buffer_size),
            device,
            queue,
            adapter: name.clone(),
        };
        if let Some(e) = pollster::block_on(scope.pop()) {
            return Err(format!("the GPU pipelines failed to build on {name}: {e}"));
        }
        tracing::info!(adapter = %name, "GPU context created");
        Ok(context)
    }
}
