//! Small constructors the compute kernels share: buffers, bind-group layout entries and bind groups whose
//! bindings are numbered in order.

use crate::gpu::context::GpuContext;

/// Invocations per workgroup of the metric and difference kernels (`LANES` in shaders/metrics.wgsl and
/// shaders/diff.wgsl): 8 on a CPU adapter (lavapipe runs a workgroup as vectors of 8 invocations and an atomic
/// one invocation at a time, so 8 invocations each reading 8 times the pixels add an eighth of the atomics per
/// pixel: benches/metric_kernel.rs), 64 on a GPU (where 8 would leave most of a warp idle).
pub fn kernel_lanes(ctx: &GpuContext) -> u32 {
    match ctx.adapter.get_info().device_type {
        wgpu::DeviceType::Cpu => 8,
        _ => 64,
    }
}

/// A buffer of `size` bytes, not mapped at creation.
pub fn buffer(
    device: &wgpu::Device,
    label: &str,
    size: u64,
    usage: wgpu::BufferUsages,
) -> wgpu::Buffer {
    device.create_buffer(&wgpu::BufferDescriptor {
        label: Some(label),
        size,
        usage,
        mapped_at_creation: false,
    })
}

/// A kernel's per-frame results on the GPU (storage, cleared and copied out) and their read-back buffer.
pub fn results_buffers(device: &wgpu::Device, labels: [&str; 2], size: u64) -> [wgpu::Buffer; 2] {
    use wgpu::BufferUsages as U;
    [
        buffer(
            device,
            labels[0],
            size,
            U::STORAGE | U::COPY_SRC | U::COPY_DST,
        ),
        buffer(device, labels[1], size, U::MAP_READ | U::COPY_DST),
    ]
}

/// A uniform buffer of `size` bytes written through the queue.
pub fn uniform_buffer(device: &wgpu::Device, label: &str, size: u64) -> wgpu::Buffer {
    buffer(
        device,
        label,
        size,
        wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
    )
}

/// A compute stage's read-write storage buffer at `binding`.
pub fn storage_entry(binding: u32) -> wgpu::BindGroupLayoutEntry {
    buffer_entry(
        binding,
        wgpu::BufferBindingType::Storage { read_only: false },
    )
}

/// A compute stage's read-only storage buffer at `binding`.
pub fn read_only_storage_entry(binding: u32) -> wgpu::BindGroupLayoutEntry {
    buffer_entry(
        binding,
        wgpu::BufferBindingType::Storage { read_only: true },
    )
}

/// A compute stage's uniform buffer at `binding`.
pub fn uniform_entry(binding: u32) -> wgpu::BindGroupLayoutEntry {
    buffer_entry(binding, wgpu::BufferBindingType::Uniform)
}

fn buffer_entry(binding: u32, ty: wgpu::BufferBindingType) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::COMPUTE,
        ty: wgpu::BindingType::Buffer {
            ty,
            has_dynamic_offset: false,
            min_binding_size: None,
        },
        count: None,
    }
}

/// A compute stage's unfilterable float 2D texture at `binding` (read with `textureLoad`).
pub fn texture_entry(binding: u32) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::COMPUTE,
        ty: wgpu::BindingType::Texture {
            sample_type: wgpu::TextureSampleType::Float { filterable: false },
            view_dimension: wgpu::TextureViewDimension::D2,
            multisampled: false,
        },
        count: None,
    }
}

/// A bind group of `resources` at bindings 0, 1, 2, ...
pub fn bind_group(
    device: &wgpu::Device,
    label: &str,
    layout: &wgpu::BindGroupLayout,
    resources: Vec<wgpu::BindingResource<'_>>,
) -> wgpu::BindGroup {
    let entries: Vec<wgpu::BindGroupEntry<'_>> = resources
        .into_iter()
        .enumerate()
        .map(|(i, resource)| wgpu::BindGroupEntry {
            binding: i as u32,
            resource,
        })
        .collect();
    device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some(label),
        layout,
        entries: &entries,
    })
}
