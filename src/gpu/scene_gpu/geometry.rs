//! The scene's meshes on the GPU: every model's LODs and every seam's meshes laid end to end in one vertex and
//! one index buffer, each LOD's range and material parts.

use crate::error::{Error, Result};
use crate::gpu::pipelines::{MaterialClass, SurfaceVertex, Vertex};
use crate::gpu::scene_gpu::pose::deformed_vertex;
use crate::scene::Scene;
use wgpu::util::DeviceExt;

/// Where one LOD of one model lives in the shared vertex and index buffers.
#[derive(Debug, Clone, Copy)]
pub struct LodRange {
    pub base_vertex: i32,
    pub first_index: u32,
    pub index_count: u32,
    /// Its material parts: `SceneGpu::parts[parts.0..parts.0 + parts.1]` (none with the flat surface).
    pub parts: (u32, u32),
}

/// A run of one LOD's indices drawn with one material.
#[derive(Debug, Clone, Copy)]
pub struct PartRange {
    pub first_index: u32,
    pub index_count: u32,
    pub material: u32,
    pub class: MaterialClass,
}

impl LodRange {
    pub fn triangles(&self) -> u64 {
        self.index_count as u64 / 3
    }
}

/// The surface vertex of vertex `v` of `mesh`: its texture coordinates, tangent and colour, defaults where the
/// mesh has none ((0, 0), +x, white).
pub fn surface_vertex(mesh: &crate::geometry::mesh::Mesh, v: usize) -> SurfaceVertex {
    let d = &mesh.data;
    let uv0 = d.uv0.as_ref().map_or([0.0; 2], |t| t[v]);
    let uv1 = d.uv1.as_ref().map_or([0.0; 2], |t| t[v]);
    SurfaceVertex {
        tex: [uv0[0], uv0[1], uv1[0], uv1[1]],
        tangent: d.tangents.as_ref().map_or([1.0, 0.0, 0.0, 1.0], |t| t[v]),
        color: d.colors.as_ref().map_or([1.0; 4], |c| c[v]),
    }
}

/// The scene's meshes laid end to end on the CPU, as [`SceneGpu`] uploads them: every model's LODs, then every
/// seam's meshes.
pub(super) struct SceneGeometry {
    pub(super) vertices: Vec<Vertex>,
    pub(super) indices: Vec<u32>,
    pub(super) lods: Vec<Vec<LodRange>>,
    pub(super) seam_base: u32,
    pub(super) parts: Vec<PartRange>,
    /// One per vertex of the models' LODs (PBR surface only).
    pub(super) surface_vertices: Vec<SurfaceVertex>,
}

impl SceneGeometry {
    /// Gathers the models' LODs (with their material parts and surface vertices when `pbr`; the `deformed`
    /// models' rest positions in `aux`), then the unified scene's seams.
    pub(super) fn gather(scene: &Scene, pbr: bool, deformed: &[u32]) -> Result<SceneGeometry> {
        let mut g = SceneGeometry {
            vertices: Vec::new(),
            indices: Vec::new(),
            lods: Vec::new(),
            seam_base: 0,
            parts: Vec::new(),
            surface_vertices: Vec::new(),
        };
        for (mi, model) in scene.models.iter().enumerate() {
            let mut ranges = Vec::new();
            for lod in &model.chain.lods {
                ranges.push(g.push_lod(scene, &lod.mesh, pbr, deformed.contains(&(mi as u32)))?);
            }
            g.lods.push(ranges);
        }
        g.seam_base = g.lods.len() as u32;
        for seam in scene.unified.iter().flat_map(|u| &u.seams) {
            let mut ranges = Vec::new();
            for m in &seam.meshes {
                ranges.push(g.push_seam_mesh(m)?);
            }
            g.lods.push(ranges);
        }
        Ok(g)
    }

    /// The base vertex of the next mesh appended.
    fn next_base_vertex(&self) -> Result<i32> {
        i32::try_from(self.vertices.len())
            .map_err(|_| Error::Gpu("scene has too many vertices".into()))
    }

    /// Appends one LOD mesh of a model (and its parts and surface vertices when `pbr`), returning its range.
    fn push_lod(
        &mut self,
        scene: &Scene,
        m: &crate::geometry::mesh::Mesh,
        pbr: bool,
        deformed: bool,
    ) -> Result<LodRange> {
        let first_part = self.parts.len() as u32;
        if pbr {
            for p in &m.parts {
                let material = &scene.materials.materials[p.material as usize];
                self.parts.push(PartRange {
                    first_index: self.indices.len() as u32 + p.first_index,
                    index_count: p.index_count,
                    material: p.material,
                    class: MaterialClass::new(
                        !material.double_sided,
                        material.alpha == crate::geometry::material::AlphaMode::Blend,
                    ),
                });
            }
            self.surface_vertices
                .extend((0..m.vertex_count()).map(|v| surface_vertex(m, v)));
        }
        let range = LodRange {
            base_vertex: self.next_base_vertex()?,
            first_index: self.indices.len() as u32,
            index_count: m.indices.len() as u32,
            parts: (first_part, self.parts.len() as u32 - first_part),
        };
        if deformed {
            self.vertices.extend(
                m.positions
                    .iter()
                    .zip(&m.normals)
                    .map(|(p, n)| deformed_vertex(*p, *n, *p)),
            );
        } else {
            self.vertices
                .extend(
                    m.positions
                        .iter()
                        .zip(&m.normals)
                        .zip(&m.aux)
                        .map(|((p, n), a)| Vertex {
                            position: *p,
                            normal: *n,
                            aux: *a,
                        }),
                );
        }
        self.indices.extend_from_slice(&m.indices);
        Ok(range)
    }

    /// Appends one mesh of a seam (no parts, `aux` zero), returning its range.
    fn push_seam_mesh(&mut self, m: &crate::scene::model::SeamMesh) -> Result<LodRange> {
        let range = LodRange {
            base_vertex: self.next_base_vertex()?,
            first_index: self.indices.len() as u32,
            index_count: m.indices.len() as u32,
            parts: (0, 0),
        };
        self.vertices
            .extend(m.positions.iter().zip(&m.normals).map(|(p, n)| Vertex {
                position: *p,
                normal: *n,
                aux: [0.0; 4],
            }));
        self.indices.extend_from_slice(&m.indices);
        Ok(range)
    }

    /// The vertex buffer (writable when some model deforms) and the index buffer.
    pub(super) fn buffers(
        &self,
        device: &wgpu::Device,
        deforms: bool,
    ) -> (wgpu::Buffer, wgpu::Buffer) {
        let vertex_buffer = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("scene vertices"),
            contents: bytemuck::cast_slice(&self.vertices),
            usage: if deforms {
                wgpu::BufferUsages::VERTEX | wgpu::BufferUsages::COPY_DST
            } else {
                wgpu::BufferUsages::VERTEX
            },
        });
        let index_buffer = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("scene indices"),
            contents: bytemuck::cast_slice(&self.indices),
            usage: wgpu::BufferUsages::INDEX,
        });
        (vertex_buffer, index_buffer)
    }
}

/// The distinct material classes of the parts, sorted; the plain class alone when there are none.
pub(super) fn material_classes(parts: &[PartRange]) -> Vec<MaterialClass> {
    let mut classes: Vec<MaterialClass> = parts.iter().map(|p| p.class).collect();
    classes.sort();
    classes.dedup();
    if classes.is_empty() {
        classes.push(MaterialClass::PLAIN);
    }
    classes
}
