//! A scene's materials on the GPU (the PBR surface, shaders/surface/pbr.wgsl): each image a texture with its
//! mipmap chain (colour images sRGB, averaged in linear light; data images linear), each glTF sampler a sampler,
//! each material a uniform and a bind group (group 2), and the surface vertex buffer (texture coordinates,
//! tangent and colour per vertex, slot 3).

use crate::error::Result;
use crate::geometry::material::{
    mip_chain, AlphaMode, Filter, Material, Materials, Sampler, TextureRef, TextureSlot, Wrap,
};
use crate::gpu::context::GpuContext;
use crate::gpu::pipelines::SurfaceVertex;
use std::collections::HashMap;
use wgpu::util::DeviceExt;

/// The material uniform of shaders/surface/pbr.wgsl (`Material`): 14 vec4s.
#[repr(C)]
#[derive(Debug, Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct MaterialRaw {
    base_color: [f32; 4],
    emissive: [f32; 4],
    factors: [f32; 4],
    alpha: [f32; 4],
    tex: [[f32; 4]; 10],
}

impl MaterialRaw {
    fn of(m: &Material) -> MaterialRaw {
        let (mode, cutoff) = match m.alpha {
            AlphaMode::Opaque => (0.0, 0.0),
            AlphaMode::Mask(c) => (1.0, c),
            AlphaMode::Blend => (2.0, 0.0),
        };
        let mut tex = [[0.0; 4]; 10];
        let slots = [
            &m.base_color_texture,
            &m.metallic_roughness_texture,
            &m.normal_texture,
            &m.occlusion_texture,
            &m.emissive_texture,
        ];
        for (k, t) in slots.iter().enumerate() {
            match t {
                Some(t) => {
                    let [r0, r1] = t.transform;
                    tex[2 * k] = [r0[0], r0[1], r0[2], f32::from(t.texcoord)];
                    tex[2 * k + 1] = [r1[0], r1[1], r1[2], 0.0];
                }
                None => tex[2 * k] = [1.0, 0.0, 0.0, -1.0],
            }
        }
        MaterialRaw {
            base_color: m.base_color,
            emissive: [m.emissive[0], m.emissive[1], m.emissive[2], 0.0],
            factors: [
                m.metallic,
                m.roughness,
                m.normal_scale,
                m.occlusion_strength,
            ],
            alpha: [mode, cutoff, if m.unlit { 1.0 } else { 0.0 }, 0.0],
            tex,
        }
    }
}

/// The materials of a scene on the GPU.
pub struct MaterialsGpu {
    pub layout: wgpu::BindGroupLayout,
    /// One bind group per material, indexed like [`Materials::materials`].
    pub groups: Vec<wgpu::BindGroup>,
    /// The surface vertex buffer, indexed like the scene's vertex buffer.
    pub vertices: wgpu::Buffer,
    /// Texture bytes uploaded, mipmaps included (run.json).
    pub texture_bytes: u64,
}

fn address(w: Wrap) -> wgpu::AddressMode {
    match w {
        Wrap::Repeat => wgpu::AddressMode::Repeat,
        Wrap::MirroredRepeat => wgpu::AddressMode::MirrorRepeat,
        Wrap::ClampToEdge => wgpu::AddressMode::ClampToEdge,
    }
}

fn filter(f: Filter) -> wgpu::FilterMode {
    match f {
        Filter::Nearest => wgpu::FilterMode::Nearest,
        Filter::Linear => wgpu::FilterMode::Linear,
    }
}

fn layout(device: &wgpu::Device) -> wgpu::BindGroupLayout {
    let mut entries = vec![wgpu::BindGroupLayoutEntry {
        binding: 0,
        visibility: wgpu::ShaderStages::FRAGMENT,
        ty: wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Uniform,
            has_dynamic_offset: false,
            min_binding_size: None,
        },
        count: None,
    }];
    for k in 0..5 {
        entries.push(wgpu::BindGroupLayoutEntry {
            binding: 1 + k,
            visibility: wgpu::ShaderStages::FRAGMENT,
            ty: wgpu::BindingType::Texture {
                sample_type: wgpu::TextureSampleType::Float { filterable: true },
                view_dimension: wgpu::TextureViewDimension::D2,
                multisampled: false,
            },
            count: None,
        });
        entries.push(wgpu::BindGroupLayoutEntry {
            binding: 6 + k,
            visibility: wgpu::ShaderStages::FRAGMENT,
            ty: wgpu::BindingType::Sampler(wgpu::SamplerBindingType::Filtering),
            count: None,
        });
    }
    entries.push(wgpu::BindGroupLayoutEntry {
        binding: 11,
        visibility: wgpu::ShaderStages::FRAGMENT,
        ty: wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Uniform,
            has_dynamic_offset: false,
            min_binding_size: None,
        },
        count: None,
    });
    device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some("material layout"),
        entries: &entries,
    })
}

/// Textures and samplers made once each, however many materials use them.
struct Cache<'a> {
    ctx: &'a GpuContext,
    materials: &'a Materials,
    views: HashMap<(u32, bool), wgpu::TextureView>,
    samplers: HashMap<Sampler, wgpu::Sampler>,
    bytes: u64,
}

impl Cache<'_> {
    /// Image `image` as a texture in `srgb` (colour) or linear (data) encoding, with every mipmap level.
    fn view(&mut self, image: u32, srgb: bool) -> wgpu::TextureView {
        if let Some(v) = self.views.get(&(image, srgb)) {
            return v.clone();
        }
        let img = &self.materials.images[image as usize];
        let levels = mip_chain(img.width, img.height, &img.rgba, srgb);
        let texture = self.ctx.device.create_texture(&wgpu::TextureDescriptor {
            label: Some(&img.name),
            size: wgpu::Extent3d {
                width: img.width,
                height: img.height,
                depth_or_array_layers: 1,
            },
            mip_level_count: levels.len() as u32,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: if srgb {
                wgpu::TextureFormat::Rgba8UnormSrgb
            } else {
                wgpu::TextureFormat::Rgba8Unorm
            },
            usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
            view_formats: &[],
        });
        for (level, (w, h, bytes)) in levels.iter().enumerate() {
            self.ctx.queue.write_texture(
                wgpu::TexelCopyTextureInfo {
                    texture: &texture,
                    mip_level: level as u32,
                    origin: wgpu::Origin3d::ZERO,
                    aspect: wgpu::TextureAspect::All,
                },
                bytes,
                wgpu::TexelCopyBufferLayout {
                    offset: 0,
                    bytes_per_row: Some(4 * w),
                    rows_per_image: Some(*h),
                },
                wgpu::Extent3d {
                    width: *w,
                    height: *h,
                    depth_or_array_layers: 1,
                },
            );
            self.bytes += bytes.len() as u64;
        }
        let view = texture.create_view(&Default::default());
        self.views.insert((image, srgb), view.clone());
        view
    }

    fn sampler(&mut self, s: Sampler) -> wgpu::Sampler {
        self.samplers
            .entry(s)
            .or_insert_with(|| {
                self.ctx.device.create_sampler(&wgpu::SamplerDescriptor {
                    label: Some("material sampler"),
                    address_mode_u: address(s.wrap_s),
                    address_mode_v: address(s.wrap_t),
                    mag_filter: filter(s.mag),
                    min_filter: filter(s.min),
                    mipmap_filter: match s.mipmap {
                        Some(Filter::Linear) => wgpu::MipmapFilterMode::Linear,
                        _ => wgpu::MipmapFilterMode::Nearest,
                    },
                    // Without mipmapping the base level alone is read.
                    lod_max_clamp: if s.mipmap.is_some() { 32.0 } else { 0.0 },
                    ..Default::default()
                })
            })
            .clone()
    }

    /// The views and samplers of `m`'s five texture slots, in binding order (`placeholder` and the default
    /// sampler where a slot has no texture).
    fn slot_bindings(
        &mut self,
        m: &Material,
        placeholder: &wgpu::TextureView,
    ) -> (Vec<wgpu::TextureView>, Vec<wgpu::Sampler>) {
        let slots: [(TextureSlot, &Option<TextureRef>); 5] = [
            (TextureSlot::BaseColor, &m.base_color_texture),
            (
                TextureSlot::MetallicRoughness,
                &m.metallic_roughness_texture,
            ),
            (TextureSlot::Normal, &m.normal_texture),
            (TextureSlot::Occlusion, &m.occlusion_texture),
            (TextureSlot::Emissive, &m.emissive_texture),
        ];
        let mut views = Vec::with_capacity(5);
        let mut samplers = Vec::with_capacity(5);
        for (slot, t) in slots {
            match t {
                Some(t) => {
                    views.push(self.view(t.image, slot.is_srgb()));
                    samplers.push(self.sampler(t.sampler));
                }
                None => {
                    views.push(placeholder.clone());
                    samplers.push(self.sampler(Sampler::default()));
                }
            }
        }
        (views, samplers)
    }

    /// Material `m`'s bind group (group 2): its uniform, its slots' views and samplers, the split-sum table.
    fn material_group(
        &mut self,
        m: &Material,
        layout: &wgpu::BindGroupLayout,
        placeholder: &wgpu::TextureView,
        dfg: &wgpu::Buffer,
    ) -> wgpu::BindGroup {
        let ctx = self.ctx;
        let uniform = ctx
            .device
            .create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("material uniform"),
                contents: bytemuck::bytes_of(&MaterialRaw::of(m)),
                usage: wgpu::BufferUsages::UNIFORM,
            });
        let (views, samplers) = self.slot_bindings(m, placeholder);
        let mut entries = vec![wgpu::BindGroupEntry {
            binding: 0,
            resource: uniform.as_entire_binding(),
        }];
        for (k, v) in views.iter().enumerate() {
            entries.push(wgpu::BindGroupEntry {
                binding: 1 + k as u32,
                resource: wgpu::BindingResource::TextureView(v),
            });
        }
        for (k, s) in samplers.iter().enumerate() {
            entries.push(wgpu::BindGroupEntry {
                binding: 6 + k as u32,
                resource: wgpu::BindingResource::Sampler(s),
            });
        }
        entries.push(wgpu::BindGroupEntry {
            binding: 11,
            resource: dfg.as_entire_binding(),
        });
        ctx.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("material"),
            layout,
            entries: &entries,
        })
    }
}

impl MaterialsGpu {
    /// Uploads `materials` and the surface vertices (`deforming`: their tangents are rewritten per frame).
    pub fn new(
        ctx: &GpuContext,
        materials: &Materials,
        vertices: &[SurfaceVertex],
        deforming: bool,
    ) -> Result<MaterialsGpu> {
        let device = &ctx.device;
        let layout = layout(device);
        let mut cache = Cache {
            ctx,
            materials,
            views: HashMap::new(),
            samplers: HashMap::new(),
            bytes: 0,
        };
        let placeholder = placeholder_view(ctx);
        let dfg = dfg_buffer(device);
        let mut groups = Vec::with_capacity(materials.materials.len());
        for m in &materials.materials {
            groups.push(cache.material_group(m, &layout, &placeholder, &dfg));
        }
        let vertices = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("surface vertices"),
            contents: bytemuck::cast_slice(vertices),
            usage: if deforming {
                wgpu::BufferUsages::VERTEX | wgpu::BufferUsages::COPY_DST
            } else {
                wgpu::BufferUsages::VERTEX
            },
        });
        let texture_bytes = cache.bytes;
        ctx.check_errors()?;
        Ok(MaterialsGpu {
            layout,
            groups,
            vertices,
            texture_bytes,
        })
    }
}

/// What a material without a texture binds in its place (never sampled: the uniform says it is absent): a
/// white 1x1 texture's view.
fn placeholder_view(ctx: &GpuContext) -> wgpu::TextureView {
    let texture = ctx.device.create_texture_with_data(
        &ctx.queue,
        &wgpu::TextureDescriptor {
            label: Some("no texture"),
            size: wgpu::Extent3d {
                width: 1,
                height: 1,
                depth_or_array_layers: 1,
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: wgpu::TextureFormat::Rgba8Unorm,
            usage: wgpu::TextureUsages::TEXTURE_BINDING,
            view_formats: &[],
        },
        wgpu::util::TextureDataOrder::LayerMajor,
        &[255, 255, 255, 255],
    );
    texture.create_view(&Default::default())
}

/// The split-sum table every material reads (shaders/surface/pbr.wgsl `dfg`), computed once per process.
fn dfg_buffer(device: &wgpu::Device) -> wgpu::Buffer {
    static DFG: std::sync::OnceLock<Vec<[f32; 2]>> = std::sync::OnceLock::new();
    device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some("split-sum table"),
        contents: bytemuck::cast_slice(DFG.get_or_init(crate::geometry::material::dfg_table)),
        usage: wgpu::BufferUsages::UNIFORM,
    })
}
