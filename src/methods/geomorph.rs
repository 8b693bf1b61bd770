//! `geomorph`: geomorphing between discrete LODs (Sheliemietiev et al. 2023 sections 10-11). A t-instance draws one mesh, the
//! finer of its two LODs, whose vertices the vertex shader moves towards their targets on the coarser LOD by the
//! morph weight (k when coarsening, 1 - k when refining), normals interpolated and renormalised, and with a
//! user scene's materials its texture coordinates, tangents and colours too, each from the texture chart the
//! vertex lies in (geometry/morph.rs). When the
//! transition ends the coarser LOD itself replaces the fully morphed finer one; what that swap leaves is
//! measured by the `pop` column on those frames. Targets come from `--correspondence` (`src/geometry/morph.rs`), computed
//! once per LOD pair and cached.

use super::common::{instance_raw, Counterfactual, FrameInput, Method};
use crate::geometry::mesh::Mesh;
use crate::geometry::morph::Correspondence;
use crate::geometry::morph::{morph_targets_by_material, MorphTargets};
use crate::gpu::{
    DrawList, DrawStats, InstanceBuffer, MeshPipeline, RenderTarget, SceneGpu, SurfaceTarget,
    Vertex,
};
use crate::scene::Scene;
use std::sync::Arc;
use wgpu::util::DeviceExt;

const STEADY: u8 = 0;
const MORPHING: u8 = 1;

/// `geomorph`'s flags.
#[derive(Debug, Clone, Copy, PartialEq, clap::Args, serde::Serialize, serde::Deserialize)]
#[serde(default, rename_all(deserialize = "kebab-case"))]
pub struct GeomorphOptions {
    /// geomorph: how fine vertices are paired with the coarse LOD (auto: surface on a glTF file, else nearest).
    #[arg(long, value_enum, value_parser = crate::defaults::names_only::<Correspondence>(),
          default_value_t = Correspondence::Auto, help_heading = crate::defaults::heading::METHODS)]
    pub correspondence: Correspondence,
}

impl Default for GeomorphOptions {
    fn default() -> Self {
        crate::defaults::clap_defaults()
    }
}

pub struct Geomorph {
    list: DrawList,
    buffer: InstanceBuffer,
    /// Per vertex of the scene's vertex buffer: its target on the next coarser LOD of its model (the coarsest
    /// LOD's vertices target themselves and are never morphed).
    targets: wgpu::Buffer,
    /// With materials: per vertex, the texture coordinates and tangent at its target (slot 4).
    surface_targets: Option<wgpu::Buffer>,
    morph: crate::gpu::MeshPipelines,
    /// The deformed models' LODs (model, LOD, first vertex, their targets): their targets follow the coarser
    /// LOD's pose every frame.
    deformed: Vec<(u32, u32, u64, Arc<MorphTargets>)>,
    /// Scratch of the followed targets.
    scratch: (Vec<[f32; 3]>, Vec<[f32; 3]>, Vec<Vertex>),
}

impl Geomorph {
    pub fn new(gpu: &SceneGpu, scene: &Scene, options: &GeomorphOptions) -> Self {
        let mut targets: Vec<Vertex> = Vec::new();
        let mut surface: Vec<SurfaceTarget> = Vec::new();
        let with_surface = gpu.materials.is_some();
        let mut deformed = Vec::new();
        let deforms = |m: usize| match &scene.motion {
            crate::scene::Motion::Animated(a) => a.deformers.iter().any(|d| d.model as usize == m),
            _ => false,
        };
        for (m, model) in scene.models.iter().enumerate() {
            let lods = &model.chain.lods;
            for (i, lod) in lods.iter().enumerate() {
                match lods.get(i + 1) {
                    Some(coarse) => {
                        let t = morph_targets_by_material(
                            &lod.mesh,
                            &coarse.mesh,
                            options.correspondence.resolve(scene.kind.is_user()),
                        );
                        if with_surface {
                            surface.extend(surface_targets(&lod.mesh, &coarse.mesh, &t));
                        }
                        if deforms(m) {
                            deformed.push((m as u32, i as u32, targets.len() as u64, t.clone()));
                        }
                        targets.extend(t.positions.iter().zip(&t.normals).map(|(p, n)| Vertex {
                            position: *p,
                            normal: *n,
                            aux: [0.0; 4],
                        }));
                    }
                    None => {
                        targets.extend(lod.mesh.positions.iter().zip(&lod.mesh.normals).map(
                            |(p, n)| Vertex {
                                position: *p,
                                normal: *n,
                                aux: [0.0; 4],
                            },
                        ));
                        if with_surface {
                            surface.extend((0..lod.mesh.vertex_count()).map(|v| {
                                let s = crate::gpu::surface_vertex(&lod.mesh, v);
                                let t = [s.tangent[0], s.tangent[1], s.tangent[2]];
                                SurfaceTarget::new(s.tex, t, s.color)
                            }));
                        }
                    }
                }
            }
        }
        Geomorph {
            list: DrawList::default(),
            buffer: gpu.create_instance_buffer("geomorph instances", scene.instances.len() as u32),
            targets: gpu
                .device
                .create_buffer_init(&wgpu::util::BufferInitDescriptor {
                    label: Some("geomorph targets"),
                    contents: bytemuck::cast_slice(&targets),
                    usage: if deformed.is_empty() {
                        wgpu::BufferUsages::VERTEX
                    } else {
                        wgpu::BufferUsages::VERTEX | wgpu::BufferUsages::COPY_DST
                    },
                }),
            surface_targets: with_surface.then(|| {
                gpu.device
                    .create_buffer_init(&wgpu::util::BufferInitDescriptor {
                        label: Some("geomorph surface targets"),
                        contents: bytemuck::cast_slice(&surface),
                        usage: wgpu::BufferUsages::VERTEX,
                    })
            }),
            deformed,
            scratch: Default::default(),
            morph: gpu.mesh_pipeline(&MeshPipeline {
                morph: true,
                ..MeshPipeline::opaque("geomorph")
            }),
        }
    }
}

/// Per vertex of `fine`, the texture coordinates, tangent and colour at its target on `coarse`: the coarse
/// vertices' of the target's sources (each the wedge of the fine vertex's texture chart at its position,
/// `geometry/morph.rs`) interpolated by their weights; the tangent renormalised (the fine vertex's where the
/// interpolation cancels).
fn surface_targets(fine: &Mesh, coarse: &Mesh, t: &MorphTargets) -> Vec<SurfaceTarget> {
    let of = |m: &Mesh, v: usize| crate::gpu::surface_vertex(m, v);
    t.surface
        .iter()
        .enumerate()
        .map(|(k, src)| {
            let mine = of(fine, k);
            let (mut tex, mut tangent, mut color) =
                (glam::Vec4::ZERO, glam::Vec3::ZERO, glam::Vec4::ZERO);
            for &(i, w) in src {
                if w != 0.0 {
                    let c = of(coarse, i as usize);
                    tex += glam::Vec4::from(c.tex) * w;
                    tangent += glam::Vec3::from_slice(&c.tangent[..3]) * w;
                    color += glam::Vec4::from(c.color) * w;
                }
            }
            let tangent = tangent
                .try_normalize()
                .unwrap_or(glam::Vec3::from_slice(&mine.tangent[..3]));
            SurfaceTarget::new(tex.to_array(), tangent.to_array(), color.to_array())
        })
        .collect()
}

impl Geomorph {
    /// The deformed models' targets on this frame's pose of their coarser LODs ([`SceneGpu::write_pose`]).
    fn follow_poses(&mut self, gpu: &SceneGpu) {
        let (ps, ns, vs) = &mut self.scratch;
        for (model, lod, first, t) in &self.deformed {
            let Some(posed) = gpu.posed(*model, lod + 1) else {
                continue;
            };
            let Some(coarse) = posed.of(*model, lod + 1) else {
                continue;
            };
            t.follow(&coarse.positions, &coarse.normals, ps, ns);
            vs.clear();
            vs.extend(ps.iter().zip(ns.iter()).map(|(p, n)| Vertex {
                position: *p,
                normal: *n,
                aux: [0.0; 4],
            }));
            gpu.queue.write_buffer(
                &self.targets,
                first * std::mem::size_of::<Vertex>() as u64,
                bytemuck::cast_slice(vs),
            );
        }
    }
}

impl Method for Geomorph {
    fn encode(
        &mut self,
        gpu: &SceneGpu,
        input: &FrameInput<'_>,
        encoder: &mut wgpu::CommandEncoder,
        target: &RenderTarget,
    ) -> DrawStats {
        self.list.clear();
        for (i, (inst, s)) in input.scene.instances.iter().zip(input.states).enumerate() {
            if s.in_transition() {
                let fine = s.lod_from.min(s.lod_to);
                let weight = if s.lod_to > s.lod_from {
                    s.k
                } else {
                    1.0 - s.k
                };
                self.list.push(
                    MORPHING,
                    inst.model,
                    fine,
                    instance_raw(input, i, weight, 1.0, fine),
                );
            } else {
                self.list.push(
                    STEADY,
                    inst.model,
                    s.lod_from,
                    instance_raw(input, i, 0.0, 1.0, s.lod_from),
                );
            }
        }
        self.list.build();
        gpu.upload(&self.buffer, &self.list);
        self.follow_poses(gpu);
        let mut pass = gpu.begin_clear_pass(encoder, target, input.view, "geomorph pass");
        pass.set_vertex_buffer(2, self.targets.slice(..));
        if let Some(s) = &self.surface_targets {
            pass.set_vertex_buffer(4, s.slice(..));
        }
        gpu.draw(
            &mut pass,
            &self.buffer,
            0,
            &self.list,
            &[&gpu.opaque_pipeline, &self.morph],
        )
    }

    fn counterfactual(&mut self) -> Option<&mut dyn Counterfactual> {
        Some(self)
    }
}

impl Counterfactual for Geomorph {
    fn image_confined_to_instances(&self) -> bool {
        true
    }
}
