//! The unified-LOD scenes (seeds 001 and 004): one large mesh divided into a 3D grid of blocks
//! ([`crate::geometry::blocks`]), each block a model of its own with its own LOD chain and one instance at the identity
//! transform, so the shared schedule selects and fades each block on its own; the seams between neighbouring
//! blocks, cross-referenced into every pair of their LODs; and the same mesh's cluster DAG for `clusterlod`.
//!
//! - `bunny-halves` (seed 004 Fig. 1): the bunny (or `--mesh`) clipped in half by the plane through its centre
//!   across x (a 2 x 1 x 1 grid), both halves with LOD0 and a LOD of a quarter of their triangles; the first
//!   half always shows LOD0, the second always the quarter (their switch distances lie beyond and inside the
//!   turntable), so the seam joins two different LODs on every frame. The camera circles the bunny once over
//!   the frames, 10 degrees above its centre, where its bounding sphere fills 80 % of the view.
//! - `terrain`: the heightfield of `src/terrain.rs` (or `--mesh`) in cubic blocks (`--blocks` along the longest
//!   side), each with LODs of 100, 25, 6.25 and 1.5625 % of its triangles, selected by projected error
//!   (`--pixel-error`). The camera flies along +z at a fixed height 3 % of the mesh's extent above its
//!   highest point, looking 10 degrees down, from 5 % before its near edge to 80 % of the way across, so near
//!   blocks are at full detail and far ones coarse.
//!
//! Switch distances of a block: where the LOD's error projects to `--pixel-error` pixels at the distance from
//! the camera to the block's bounding sphere (distance to the centre minus the radius, the rule
//! `clusterlod`'s cut uses too), i.e. [`crate::geometry::lod::switch_distance`] plus the radius, spread so that
//! consecutive transition bands never overlap.

use super::kind::SceneKind;
use crate::error::{Error, Result};
use crate::geometry::blocks::{BlockLod, Grid, Partition, PartitionMode};
use crate::geometry::cluster_dag::ClusterDag;
use crate::geometry::lod::{Lod, LodChain};
use crate::geometry::mesh::Mesh;
use crate::scene::schedule::ScheduleParams;
use glam::{DVec3, Vec3};
use serde::Serialize;
use std::sync::Arc;

/// LOD targets of the terrain's blocks: each a quarter of the one before (what combining 2 x 2 blocks into
/// one of the same triangle count gives in Blow's hierarchy).
pub const TERRAIN_TARGETS: [f32; 4] = [1.0, 0.25, 0.0625, 0.015625];
/// LOD targets of bunny-halves' halves (seed 004 Fig. 1c: "decreasing its triangle count by a factor of 4").
pub const HALVES_TARGETS: [f32; 2] = [1.0, 0.25];
/// Colour of the terrain (linear RGB).
pub const TERRAIN_COLOR: [f32; 3] = [0.36, 0.45, 0.22];
/// Colour of bunny-halves (the bunny's).
pub const BUNNY_COLOR: [f32; 3] = [0.72, 0.45, 0.28];

/// One seam mesh: the seam between two blocks at one pair of their LODs (empty where every quad is
/// degenerate). Positions and normals are copies of the blocks' own, bit for bit, so the seam's edges are the
/// blocks' edges exactly.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct SeamMesh {
    pub positions: Vec<[f32; 3]>,
    pub normals: Vec<[f32; 3]>,
    pub indices: Vec<u32>,
}

/// The seams between blocks (models) `blocks.0` and `blocks.1`: `meshes[a * lods.1 + b]` joins the first at
/// LOD a to the second at LOD b.
#[derive(Debug, Clone)]
pub struct Seam {
    pub blocks: (u32, u32),
    pub lods: (u32, u32),
    pub meshes: Vec<SeamMesh>,
}

impl Seam {
    pub fn mesh_index(&self, a: u32, b: u32) -> u32 {
        a.min(self.lods.0 - 1) * self.lods.1 + b.min(self.lods.1 - 1)
    }
}

/// What the preprocessing took and made (describe and run.json's scene descriptions).
#[derive(Debug, Clone, Serialize)]
pub struct Preprocessing {
    pub partition: PartitionMode,
    pub grid: [u32; 3],
    pub block_size: f64,
    pub blocks: usize,
    pub input_triangles: usize,
    /// Triangles of all blocks at full resolution (clipping adds some).
    pub block_triangles: usize,
    pub lod_targets: Vec<f32>,
    pub seam_pairs: usize,
    pub seam_edges: usize,
    /// Seam triangles over every pair of LODs of every pair of blocks.
    pub seam_triangles_all_lod_pairs: usize,
    pub partition_ms: f64,
    pub lod_chains_ms: f64,
    pub seams_ms: f64,
    /// Partition + LOD chains + seams: the blocks' whole preprocessing.
    pub blocks_ms: f64,
    /// Bytes of the blocks' LOD meshes and the seams as the GPU holds them (40-byte vertices, 4-byte indices).
    pub blocks_bytes: u64,
    pub seams_bytes: u64,
    pub clusterlod_ms: f64,
    pub clusterlod_bytes: u64,
    pub clusters: usize,
    pub cluster_groups: usize,
    pub cluster_levels: u32,
}

/// A unified scene's mesh, seams and cluster DAG (shared by every block of the scene).
#[derive(Debug)]
pub struct Unified {
    /// The whole mesh (clusterlod draws it).
    pub mesh: Mesh,
    pub dag: ClusterDag,
    pub seams: Vec<Seam>,
    /// `--pixel-error` as the blocks' switch distances and clusterlod's cut use it.
    pub pixel_error: f32,
    pub preprocessing: Preprocessing,
}

/// Bytes of a vertex on the GPU (`gpu::Vertex`: position, normal, aux).
const VERTEX_BYTES: u64 = 40;

/// Where the unified scenes' camera goes.
#[derive(Debug, Clone, Copy)]
pub enum UnifiedCamera {
    /// A flight from `.0` to `.1` looking along the scene's `forward`.
    Flight(Vec3, Vec3),
    /// Once around `center` at `distance`, `elevation` radians above it.
    Turntable {
        center: Vec3,
        distance: f32,
        elevation: f32,
    },
}

/// One block as the scene's model of it (`SceneDef` makes a `Model` and one instance of each).
#[derive(Debug, Clone)]
pub struct BlockModel {
    pub name: String,
    pub color: [f32; 3],
    pub chain: LodChain,
    pub switches: Vec<f32>,
    pub switch_source: &'static str,
    /// Bounding-sphere centre and radius of LOD0 (world units: blocks are at the identity transform).
    pub center: Vec3,
    pub radius: f32,
}

/// Everything `SceneDef` needs of a unified scene.
pub struct UnifiedDef {
    pub blocks: Vec<BlockModel>,
    pub unified: Arc<Unified>,
    pub camera: UnifiedCamera,
    pub forward: Vec3,
    pub near: f32,
    pub far: f32,
}

/// What a unified scene is built from: its mesh (named `mesh_source` in errors), the flags that shape it, and
/// the viewport.
pub struct UnifiedInput<'a> {
    pub kind: SceneKind,
    pub mesh: Mesh,
    pub mesh_source: &'a str,
    pub partition: PartitionMode,
    /// terrain: blocks along the longest side.
    pub blocks: u32,
    pub pixel_error: f32,
    pub schedule: &'a ScheduleParams,
    pub width: u32,
    pub height: u32,
    pub fov_y: f32,
}

/// Builds `input.kind`'s blocks, seams and DAG.
pub fn build(input: UnifiedInput<'_>) -> Result<UnifiedDef> {
    let UnifiedInput {
        kind,
        mesh,
        mesh_source,
        partition: partition_mode,
        blocks,
        pixel_error,
        schedule,
        width,
        height,
        fov_y,
    } = input;
    let name = kind.name();
    mesh.check_area(mesh_source)?;
    let (lo, hi) = mesh.bounds();
    let extent = (hi - lo).max_element();
    if !(extent.is_finite() && extent > 0.0) {
        return Err(Error::Mesh {
            path: mesh_source.to_string(),
            problem: "has zero extent".into(),
        });
    }
    let halves = kind == SceneKind::BunnyHalves;
    let grid = if halves {
        // Two cubes side by side, meeting in the plane x = the mesh's centre.
        let cell = extent as f64 * 1.01;
        let centre = ((lo.x + hi.x) * 0.5) as f64;
        Grid {
            origin: DVec3::new(
                centre - cell,
                lo.y as f64 - 0.005 * cell,
                lo.z as f64 - 0.005 * cell,
            ),
            cell,
            dims: [2, 1, 1],
        }
    } else {
        Grid::covering(
            &mesh.positions,
            extent as f64 / blocks as f64 * (1.0 + 1e-6),
        )?
    };
    let started = std::time::Instant::now();
    let partition = match partition_mode {
        PartitionMode::Clip => Partition::clip(&mesh.positions, &mesh.indices, grid),
        PartitionMode::Bin => Partition::bin(&mesh.positions, &mesh.indices, grid),
    };
    let partition_ms = started.elapsed().as_secs_f64() * 1e3;
    let targets: &[f32] = if halves {
        &HALVES_TARGETS
    } else {
        &TERRAIN_TARGETS
    };
    let started = std::time::Instant::now();
    let mut chains = partition.lod_chains(targets)?;
    // A LOD the simplifier emptied (a sliver of a block) repeats the one before.
    for chain in &mut chains {
        for l in 1..chain.len() {
            if chain[l].indices.is_empty() {
                chain[l] = chain[l - 1].clone();
            }
        }
    }
    let normals = partition.vertex_normals(&mesh.positions, &mesh.normals, &mesh.indices);
    let color = if halves { BUNNY_COLOR } else { TERRAIN_COLOR };
    let mut models = Vec::with_capacity(partition.blocks.len());
    let mut blocks_bytes = 0u64;
    for (bi, (b, chain)) in partition.blocks.iter().zip(&chains).enumerate() {
        let block_name = format!("{name} block {},{},{}", b.coord[0], b.coord[1], b.coord[2]);
        let full = Mesh::new(
            &block_name,
            b.positions.clone(),
            Some(normals[bi].clone()),
            b.indices.clone(),
        )?;
        let lods = chain
            .iter()
            .zip(targets)
            .map(|(l, &f)| {
                Ok(Lod {
                    mesh: crate::geometry::lod::compact(&block_name, &full, &l.indices)?,
                    target_fraction: f,
                    error_abs: l.error_abs,
                })
            })
            .collect::<Result<Vec<_>>>()?;
        blocks_bytes += lods
            .iter()
            .map(|l| l.mesh.vertex_count() as u64 * VERTEX_BYTES + l.mesh.indices.len() as u64 * 4)
            .sum::<u64>();
        let (center, radius) = lods[0].mesh.bounding_sphere();
        models.push(BlockModel {
            name: block_name,
            color,
            chain: LodChain { lods },
            switches: Vec::new(),
            switch_source: if halves { "scene" } else { "pixel-error" },
            center,
            radius,
        });
    }
    let lod_chains_ms = started.elapsed().as_secs_f64() * 1e3;

    let started = std::time::Instant::now();
    let pairs = partition.seam_pairs();
    let mut seams = Vec::with_capacity(pairs.len());
    let mut seam_triangles = 0;
    let mut seams_bytes = 0u64;
    for pair in &pairs {
        let (a, b) = pair.blocks;
        let (la, lb) = (chains[a].len(), chains[b].len());
        let mut meshes = Vec::with_capacity(la * lb);
        for lod_a in &chains[a] {
            for lod_b in &chains[b] {
                let m = seam_mesh(&partition, &normals, pair, lod_a, lod_b);
                seam_triangles += m.indices.len() / 3;
                seams_bytes += m.positions.len() as u64 * VERTEX_BYTES + m.indices.len() as u64 * 4;
                meshes.push(m);
            }
        }
        seams.push(Seam {
            blocks: (a as u32, b as u32),
            lods: (la as u32, lb as u32),
            meshes,
        });
    }
    let seams_ms = started.elapsed().as_secs_f64() * 1e3;

    let dag = ClusterDag::build(mesh_source, &mesh)?;

    // The camera, then the switch distances (bunny-halves' depend on the turntable's distance).
    let aspect = width as f32 / height as f32;
    let half_fov = (fov_y * 0.5).min(((fov_y * 0.5).tan() * aspect).atan());
    let (camera, forward, near, far) = if halves {
        let (center, radius) = mesh.bounding_sphere();
        let distance = radius / half_fov.sin() / 0.8;
        (
            UnifiedCamera::Turntable {
                center,
                distance,
                elevation: 10f32.to_radians(),
            },
            -Vec3::Z,
            radius * 0.02,
            distance + 4.0 * radius,
        )
    } else {
        let pitch = 10f32.to_radians();
        let y = hi.y + 0.03 * extent;
        let x = (lo.x + hi.x) * 0.5;
        let (z0, z1) = (lo.z - 0.05 * extent, lo.z + 0.8 * (hi.z - lo.z));
        (
            UnifiedCamera::Flight(Vec3::new(x, y, z0), Vec3::new(x, y, z1)),
            Vec3::new(0.0, -pitch.sin(), pitch.cos()),
            extent * 5e-4,
            extent * 2.0,
        )
    };
    let band_ratio = (1.0 + schedule.band) * (1.0 + schedule.hysteresis)
        / ((1.0 - schedule.band) * (1.0 - schedule.hysteresis))
        * 1.01;
    for (bi, m) in models.iter_mut().enumerate() {
        m.switches = match camera {
            UnifiedCamera::Turntable { distance, .. } => {
                // The first half never leaves LOD0, the second never shows it.
                vec![if bi == 0 {
                    distance * 1e3
                } else {
                    distance * 0.05
                }]
            }
            UnifiedCamera::Flight(..) => {
                let mut out: Vec<f32> = Vec::new();
                for lod in &m.chain.lods[1..] {
                    let d = crate::geometry::lod::switch_distance(
                        lod.error_abs,
                        1.0,
                        pixel_error,
                        height,
                        fov_y,
                    ) + m.radius;
                    let d = match out.last() {
                        Some(&prev) if d < prev * band_ratio => prev * band_ratio,
                        _ => d,
                    };
                    out.push(d);
                }
                out
            }
        };
        schedule.check_switches(&m.name, &m.switches)?;
    }
    let preprocessing = Preprocessing {
        partition: partition.mode,
        grid: partition.grid.dims,
        block_size: partition.grid.cell,
        blocks: partition.blocks.len(),
        input_triangles: mesh.triangle_count(),
        block_triangles: partition.triangle_count(),
        lod_targets: targets.to_vec(),
        seam_pairs: pairs.len(),
        seam_edges: partition.seams.len(),
        seam_triangles_all_lod_pairs: seam_triangles,
        partition_ms,
        lod_chains_ms,
        seams_ms,
        blocks_ms: partition_ms + lod_chains_ms + seams_ms,
        blocks_bytes,
        seams_bytes,
        clusterlod_ms: dag.build_ms,
        clusterlod_bytes: dag.bytes() + mesh.vertex_count() as u64 * VERTEX_BYTES,
        clusters: dag.clusters.len(),
        cluster_groups: dag.groups.len(),
        cluster_levels: dag.levels(),
    };
    Ok(UnifiedDef {
        blocks: models,
        unified: Arc::new(Unified {
            mesh,
            dag,
            seams,
            pixel_error,
            preprocessing,
        }),
        camera,
        forward,
        near,
        far,
    })
}

/// The seam of `pair` between its blocks at LODs `a` and `b` as a mesh of its own (three vertices a
/// triangle, copied from the blocks).
fn seam_mesh(
    partition: &Partition,
    normals: &[Vec<[f32; 3]>],
    pair: &crate::geometry::blocks::SeamPair,
    a: &BlockLod,
    b: &BlockLod,
) -> SeamMesh {
    let mut m = SeamMesh::default();
    let blocks = [pair.blocks.0, pair.blocks.1];
    for t in pair.triangles(partition, a, b) {
        for (side, v) in t {
            let block = blocks[side];
            m.indices.push(m.positions.len() as u32);
            m.positions
                .push(partition.blocks[block].positions[v as usize]);
            m.normals.push(normals[block][v as usize]);
        }
    }
    m
}
