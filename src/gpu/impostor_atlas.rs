//! `--impostor`'s atlases on the GPU (`geometry/impostor.rs` is the CPU half): two 2D array textures, two layers
//! per impostor each (sRGB: base colour with coverage, emissive; linear: the object-space normal with depth,
//! occlusion-roughness-metallic), the table the shader reads (settings, each slot's bounding sphere), and the
//! bake: each model's LOD0 drawn with the scene's own surface, from each frame's direction, orthographic, into
//! its frame of the atlas (`fs_bake` in shaders/mesh.wgsl). The atlases are bound in group 0 beside the camera,
//! so every method's pipelines read them.
//!
//! Baking is deterministic: the same scene and flags give the same atlas bytes on an adapter (a test reads them
//! twice). What is not baked: a deformed model's animation (its rest pose is), a windmill's spinning blades
//! (at rest), a BLEND material's translucency (baked as covered).

use crate::error::{Error, Result};
use crate::geometry::impostor::{
    ends_in_card, frame_basis, frame_direction, Impostor, Layout, LAYERS_PER_IMPOSTOR,
    MAX_IMPOSTORS,
};
use crate::geometry::projection::Sphere;
use crate::gpu::draw_list::{DrawList, InstanceRaw};
use crate::gpu::instances::InstanceBuffer;
use crate::gpu::pipelines::MeshPipelines;
use crate::scene::Scene;
use glam::{Mat4, Vec3, Vec4};

use crate::formats::{IMPOSTOR_LINEAR_FORMAT as LINEAR, IMPOSTOR_SRGB_FORMAT as SRGB};

/// A model with an impostor: its index, slot (its card's `aux.w`) and bounding sphere (object space).
#[derive(Debug, Clone, Copy)]
pub struct ImpostorSlot {
    pub model: u32,
    pub slot: u32,
    pub sphere: Sphere,
}

/// The impostors' slots of `scene`: each model whose last level is a card.
pub fn slots(scene: &Scene) -> Vec<ImpostorSlot> {
    scene
        .models
        .iter()
        .enumerate()
        .filter(|(_, m)| ends_in_card(&m.chain))
        .filter_map(|(i, m)| {
            let last = m.chain.lods.last()?;
            Some(ImpostorSlot {
                model: i as u32,
                slot: last.mesh.aux[0][3] as u32,
                sphere: Sphere::new(m.center, m.radius / m.scale),
            })
        })
        .collect()
}

/// The atlases, their views, sampler and table; 1 x 1 placeholders where the scene has no impostor.
pub struct ImpostorAtlas {
    pub srgb: wgpu::Texture,
    pub linear: wgpu::Texture,
    pub srgb_view: wgpu::TextureView,
    pub linear_view: wgpu::TextureView,
    pub sampler: wgpu::Sampler,
    pub table: wgpu::Buffer,
    pub slots: Vec<ImpostorSlot>,
    pub impostor: Option<Impostor>,
}

/// The shader's `Impostors` table: settings, atlas scale, 64 spheres.
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct TableRaw {
    settings: [f32; 4],
    atlas: [f32; 4],
    spheres: [[f32; 4]; MAX_IMPOSTORS],
}

fn array_texture(
    device: &wgpu::Device,
    label: &str,
    side: u32,
    layers: u32,
    format: wgpu::TextureFormat,
) -> wgpu::Texture {
    device.create_texture(&wgpu::TextureDescriptor {
        label: Some(label),
        size: wgpu::Extent3d {
            width: side,
            height: side,
            depth_or_array_layers: layers,
        },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format,
        usage: wgpu::TextureUsages::RENDER_ATTACHMENT
            | wgpu::TextureUsages::TEXTURE_BINDING
            | wgpu::TextureUsages::COPY_SRC,
        view_formats: &[],
    })
}

fn array_view(t: &wgpu::Texture) -> wgpu::TextureView {
    t.create_view(&wgpu::TextureViewDescriptor {
        dimension: Some(wgpu::TextureViewDimension::D2Array),
        ..Default::default()
    })
}

impl ImpostorAtlas {
    /// The atlases of `scene`'s impostors (empty until [`ImpostorAtlas::bake`]); an atlas larger than the
    /// adapter allows is refused.
    pub fn new(device: &wgpu::Device, queue: &wgpu::Queue, scene: &Scene) -> Result<ImpostorAtlas> {
        let slots = slots(scene);
        let impostor = scene.impostor.filter(|_| !slots.is_empty());
        let (side, layers) = match &impostor {
            Some(imp) => {
                let limits = device.limits();
                if imp.resolution > limits.max_texture_dimension_2d {
                    return Err(Error::Config(format!(
                        "--impostor-resolution {}: this adapter's largest texture side is {}; bake a smaller \
                         atlas",
                        imp.resolution, limits.max_texture_dimension_2d
                    )));
                }
                let layers = slots.len() as u32 * LAYERS_PER_IMPOSTOR;
                if layers > limits.max_texture_array_layers {
                    return Err(Error::Config(format!(
                        "--impostor: {} impostors need {layers} atlas layers; this adapter allows {}",
                        slots.len(),
                        limits.max_texture_array_layers
                    )));
                }
                (imp.resolution, layers)
            }
            None => (1, LAYERS_PER_IMPOSTOR),
        };
        Ok(ImpostorAtlas::build(
            device,
            queue,
            (side, layers),
            slots,
            impostor,
        ))
    }

    /// Placeholders (what the bake's own camera group binds: an atlas is never read while it is drawn).
    pub fn empty(device: &wgpu::Device, queue: &wgpu::Queue) -> ImpostorAtlas {
        ImpostorAtlas::build(device, queue, (1, LAYERS_PER_IMPOSTOR), Vec::new(), None)
    }

    fn build(
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        (side, layers): (u32, u32),
        slots: Vec<ImpostorSlot>,
        impostor: Option<Impostor>,
    ) -> ImpostorAtlas {
        let srgb = array_texture(device, "impostor atlas (sRGB)", side, layers, SRGB);
        let linear = array_texture(device, "impostor atlas (linear)", side, layers, LINEAR);
        let sampler = device.create_sampler(&wgpu::SamplerDescriptor {
            label: Some("impostor sampler"),
            address_mode_u: wgpu::AddressMode::ClampToEdge,
            address_mode_v: wgpu::AddressMode::ClampToEdge,
            mag_filter: wgpu::FilterMode::Linear,
            min_filter: wgpu::FilterMode::Linear,
            ..Default::default()
        });
        let table = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("impostor table"),
            size: std::mem::size_of::<TableRaw>() as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let mut raw: TableRaw = bytemuck::Zeroable::zeroed();
        if let Some(imp) = &impostor {
            raw.settings = [
                imp.frames as f32,
                if imp.layout == Layout::Hemi { 1.0 } else { 0.0 },
                imp.blend as f32,
                if imp.parallax { 1.0 } else { 0.0 },
            ];
            raw.atlas = [
                imp.frame_texels() as f32 / imp.resolution as f32,
                0.0,
                0.0,
                0.0,
            ];
            for s in &slots {
                raw.spheres[s.slot as usize] = s.sphere.centre.extend(s.sphere.radius).to_array();
            }
        }
        queue.write_buffer(&table, 0, bytemuck::bytes_of(&raw));
        ImpostorAtlas {
            srgb_view: array_view(&srgb),
            linear_view: array_view(&linear),
            srgb,
            linear,
            sampler,
            table,
            slots,
            impostor,
        }
    }
}

/// The orthographic view-projection of a frame: `f` the view direction (towards the camera), the sphere filling
/// the frame, depth 0 at the sphere's front and 1 at its back.
pub fn frame_view_proj(sphere: &Sphere, f: Vec3) -> Mat4 {
    let (right, up) = frame_basis(f);
    let (c, r) = (sphere.centre, sphere.radius);
    let rows = [
        (right / r).extend(-c.dot(right) / r),
        (up / r).extend(-c.dot(up) / r),
        (-f / (2.0 * r)).extend((r + c.dot(f)) / (2.0 * r)),
        Vec4::W,
    ];
    Mat4::from_cols(rows[0], rows[1], rows[2], rows[3]).transpose()
}

/// What the bake draws with: the scene's bake pipelines (`fs_bake`), its camera group over the bake's camera
/// buffer, one instance at the identity.
pub struct Baker<'a> {
    pub device: &'a wgpu::Device,
    pub queue: &'a wgpu::Queue,
    pub pipelines: &'a MeshPipelines,
    pub camera_group: &'a wgpu::BindGroup,
    pub camera_buffer: &'a wgpu::Buffer,
    pub instance: &'a InstanceBuffer,
}

/// The bake camera's uniform for a frame (the layout of `CameraRaw` in scene_gpu/camera.rs, written whole).
pub fn bake_camera_words(sphere: &Sphere, f: Vec3) -> Vec<f32> {
    let l = Vec3::from(crate::scene::model::LIGHT_DIR).normalize();
    let mut w = Vec::with_capacity(64);
    w.extend(frame_view_proj(sphere, f).to_cols_array());
    w.extend(
        (sphere.centre + f * (2.0 * sphere.radius))
            .extend(1.0)
            .to_array(),
    );
    w.extend([l.x, l.y, l.z, crate::scene::model::AMBIENT]);
    w.extend([0.0; 16]);
    w.extend([0.0; 4]);
    w.extend([0.0; 4]);
    w.extend(sphere.centre.extend(sphere.radius).to_array());
    w
}

impl ImpostorAtlas {
    /// Bakes every impostor's frames through `baker`, a submission per frame; `draw` records the model's LOD0
    /// at the bake's instance into a pass.
    pub fn bake(
        &self,
        baker: &Baker<'_>,
        draw: &dyn Fn(&mut wgpu::RenderPass<'_>, &DrawList),
    ) -> Result<()> {
        let Some(imp) = &self.impostor else {
            return Ok(());
        };
        let fp = imp.frame_texels();
        let depth = crate::gpu::targets::texture_2d(
            baker.device,
            "impostor bake depth",
            (imp.resolution, imp.resolution),
            crate::formats::DEPTH_FORMAT,
            wgpu::TextureUsages::RENDER_ATTACHMENT,
        );
        let depth_view = depth.create_view(&Default::default());
        let identity =
            InstanceRaw::new(&Mat4::IDENTITY, [1.0, 1.0, 1.0, 0.0], [0.0, 1.0, 0.0, 0.0]);
        let mut list = DrawList::default();
        for s in &self.slots {
            list.clear();
            list.push(0, s.model, 0, identity);
            list.build();
            baker
                .instance
                .write(baker.queue, 0, &list, &Default::default());
            let layer = |t: &wgpu::Texture, l: u32| {
                t.create_view(&wgpu::TextureViewDescriptor {
                    dimension: Some(wgpu::TextureViewDimension::D2),
                    base_array_layer: s.slot * LAYERS_PER_IMPOSTOR + l,
                    array_layer_count: Some(1),
                    ..Default::default()
                })
            };
            let views = [
                layer(&self.srgb, 0),
                layer(&self.srgb, 1),
                layer(&self.linear, 0),
                layer(&self.linear, 1),
            ];
            for j in 0..imp.frames {
                for i in 0..imp.frames {
                    let f = frame_direction(imp.layout, imp.frames, i, j);
                    let words = bake_camera_words(&s.sphere, f);
                    baker
                        .queue
                        .write_buffer(baker.camera_buffer, 0, bytemuck::cast_slice(&words));
                    let first = i == 0 && j == 0;
                    let mut encoder = baker.device.create_command_encoder(&Default::default());
                    {
                        let mut pass = begin_bake_pass(&mut encoder, &views, &depth_view, first);
                        pass.set_bind_group(0, baker.camera_group, &[]);
                        let (x, y) = ((i * fp) as f32, (j * fp) as f32);
                        pass.set_viewport(x, y, fp as f32, fp as f32, 0.0, 1.0);
                        pass.set_scissor_rect(i * fp, j * fp, fp, fp);
                        draw(&mut pass, &list);
                    }
                    baker.queue.submit([encoder.finish()]);
                }
            }
        }
        Ok(())
    }
}

/// A bake pass over the four layers of a slot (cleared to zero on its first frame) and the depth (cleared).
fn begin_bake_pass<'e>(
    encoder: &'e mut wgpu::CommandEncoder,
    views: &[wgpu::TextureView; 4],
    depth: &wgpu::TextureView,
    clear: bool,
) -> wgpu::RenderPass<'e> {
    let load = if clear {
        wgpu::LoadOp::Clear(wgpu::Color::TRANSPARENT)
    } else {
        wgpu::LoadOp::Load
    };
    let attachments: Vec<Option<wgpu::RenderPassColorAttachment<'_>>> = views
        .iter()
        .map(|v| {
            Some(wgpu::RenderPassColorAttachment {
                view: v,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations {
                    load,
                    store: wgpu::StoreOp::Store,
                },
            })
        })
        .collect();
    encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
        label: Some("impostor bake"),
        color_attachments: &attachments,
        depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
            view: depth,
            depth_ops: Some(wgpu::Operations {
                load: wgpu::LoadOp::Clear(1.0),
                store: wgpu::StoreOp::Store,
            }),
            stencil_ops: None,
        }),
        timestamp_writes: None,
        occlusion_query_set: None,
        multiview_mask: None,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The frame's projection puts the sphere's front at depth 0, its back at 1, its right edge at x = 1 and its
    /// top at y = 1.
    #[test]
    fn a_frame_projects_its_sphere_onto_the_frame() {
        let s = Sphere::new(Vec3::new(1.0, 2.0, 3.0), 2.0);
        for f in [
            Vec3::Y,
            Vec3::X,
            Vec3::new(0.3, -0.5, 0.8).normalize(),
            Vec3::NEG_Y,
        ] {
            let m = frame_view_proj(&s, f);
            let (right, up) = frame_basis(f);
            let p = |q: Vec3| m.project_point3(q);
            assert!((p(s.centre + f * 2.0).z).abs() < 1e-5);
            assert!((p(s.centre - f * 2.0).z - 1.0).abs() < 1e-5);
            assert!((p(s.centre + right * 2.0).x - 1.0).abs() < 1e-5);
            assert!((p(s.centre + up * 2.0).y - 1.0).abs() < 1e-5);
        }
    }
}
