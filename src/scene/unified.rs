//! The unified-LOD scenes (Blow 2003, Unified Rendering LOD Parts 2 and 3): one large mesh divided into a 3D
//! grid of blocks ([`crate::geometry::blocks`]), each block a model of its own with its own LOD chain and one
//! instance at the identity transform, so the shared schedule selects and fades each block on its own; the
//! seams between neighbouring blocks, cross-referenced into every pair of their LODs; and the same mesh's
//! cluster DAG for `clusterlod`.
//!
//! - `bunny-halves` (Blow 2003, Part 3, Fig. 1): the bunny (or `--mesh`) clipped in half by the plane through
//!   its centre across x (a 2 x 1 x 1 grid), both halves with LOD0 and a LOD of a quarter of their triangles;
//!   the first half always shows LOD0, the second always the quarter (their switch distances lie beyond and
//!   inside the turntable), so the seam joins two different LODs on every frame. The camera circles the bunny
//!   once over the frames, 10 degrees above its centre, where its bounding sphere fills 80 % of the view.
//! - `terrain`: the heightfield of `geometry/terrain.rs` (or `--mesh`) in cubic blocks (`--blocks` along the
//!   longest side), each with LODs of 100, 25, 6.25 and 1.5625 % of its triangles, selected by projected
//!   error (`--pixel-error`). The camera flies along +z at a fixed height 3 % of the mesh's extent above its
//!   highest point, looking 10 degrees down, from 5 % before its near edge to 80 % of the way across, so near
//!   blocks are at full detail and far ones coarse.
//!
//! Switch distances of a block: where the LOD's error projects to `--pixel-error` pixels at the distance from
//! the camera to the block's bounding sphere (distance to the centre minus the radius, the rule
//! `clusterlod`'s cut uses too), i.e. [`crate::geometry::lod::switch_distance`] plus the radius, spread so that
//! consecutive transition bands never overlap.

use crate::error::{Error, Result};
use crate::geometry::blocks::{BlockLod, Grid, Partition, PartitionMode, SeamPair};
use crate::geometry::cluster_dag::ClusterDag;
use crate::geometry::lod::{Lod, LodChain};
use crate::geometry::mesh::Mesh;
use crate::geometry::projection::{fit_distance, Sphere};
use crate::geometry::terrain::TerrainField;
use crate::scene::bunny::{self, BUNNY_COLOR};
use crate::scene::config::SceneConfig;
use crate::scene::kind::{ProfileValues, SceneKind};
use crate::scene::model::{
    CameraTrack, Instance, Layout, Model, ModelSet, Motion, SwitchSource, SCENE_SEED,
};
/// The unified scenes' data, defined with the rest of the data model.
pub use crate::scene::model::{Preprocessing, Seam, SeamMesh, Unified};
use crate::scene::schedule::ScheduleParams;
use glam::{DVec3, Vec3};
use std::sync::Arc;
use std::time::Instant;

/// LOD targets of the terrain's blocks: each a quarter of the one before (what combining 2 x 2 blocks into
/// one of the same triangle count gives in Blow's hierarchy).
pub const TERRAIN_TARGETS: [f32; 4] = [1.0, 0.25, 0.0625, 0.015625];
/// LOD targets of bunny-halves' halves (Blow 2003, Part 3, Fig. 1c: "decreasing its triangle count by a
/// factor of 4").
pub const HALVES_TARGETS: [f32; 2] = [1.0, 0.25];
/// Colour of the terrain (linear RGB).
pub const TERRAIN_COLOR: [f32; 3] = [0.36, 0.45, 0.22];

/// Bytes of a vertex on the GPU (`gpu::Vertex`: position, normal, aux).
const VERTEX_BYTES: u64 = 40;

/// What a unified scene's blocks are built from, once per scene: one instance per block (at the identity
/// transform), the mesh, seams and DAG they share, and the camera.
#[derive(Debug)]
pub struct UnifiedParts {
    pub instances: Vec<Instance>,
    pub data: Arc<Unified>,
    pub camera: CameraTrack,
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
    /// The procedural terrain's height field, when the mesh is it (for `roam`).
    pub terrain: Option<TerrainField>,
}

/// Unified scene `kind`: its mesh (`--mesh`, the built-in bunny, or the terrain), its blocks as models with
/// one instance each, and its seams and cluster DAG.
pub fn def(
    kind: SceneKind,
    cfg: &SceneConfig,
    pv: &ProfileValues,
    fov_y: f32,
) -> Result<(ModelSet, UnifiedParts)> {
    if cfg.switch_distances.is_some() {
        return Err(Error::Config(format!(
            "--switch-distances does not apply to {}: each of its blocks has switch distances of its own (set \
             --pixel-error)",
            kind.name()
        )));
    }
    let started = Instant::now();
    let (mesh, mesh_source) = load_mesh(kind, cfg)?;
    let (models, parts) = build(UnifiedInput {
        kind,
        mesh,
        mesh_source: &mesh_source,
        partition: cfg.partition,
        blocks: cfg
            .blocks
            .unwrap_or_else(|| SceneKind::terrain_blocks(cfg.profile)),
        pixel_error: cfg.pixel_error(kind, pv.height),
        schedule: &cfg.schedule,
        width: pv.width,
        height: pv.height,
        fov_y,
        terrain: (kind == SceneKind::Terrain && cfg.mesh.is_none()).then(|| TerrainField {
            seed: SCENE_SEED,
            quads: SceneKind::terrain_quads(cfg.profile),
            blocks: cfg
                .blocks
                .unwrap_or_else(|| SceneKind::terrain_blocks(cfg.profile)),
        }),
    })?;
    let set = ModelSet {
        models,
        mesh_source,
        lod_generation_ms: started.elapsed().as_secs_f64() * 1e3,
        notes: Vec::new(),
    };
    Ok((set, parts))
}

/// The mesh of unified scene `kind` and its `mesh_source`: `--mesh`, else the built-in bunny (bunny-halves) or
/// the procedural terrain.
fn load_mesh(kind: SceneKind, cfg: &SceneConfig) -> Result<(Mesh, String)> {
    let quads = SceneKind::terrain_quads(cfg.profile);
    Ok(match (&cfg.mesh, kind) {
        (Some(p), _) => (Mesh::load(p)?, p.display().to_string()),
        (None, SceneKind::BunnyHalves) => {
            (bunny::built_in_mesh()?, bunny::BUILT_IN_SOURCE.to_string())
        }
        (None, _) => (
            crate::geometry::terrain::terrain_mesh(SCENE_SEED, quads)?,
            format!("procedural (src/geometry/terrain.rs, seed SCENE_SEED = 2008, {quads} x {quads} cells)"),
        ),
    })
}

/// A unified scene's block instances for any count: one per block, the camera on its track.
pub fn layout(u: &UnifiedParts) -> Layout {
    let eye = match &u.camera {
        CameraTrack::Path(p) => p.view(0, 1).0,
        &CameraTrack::Flight(from, _) => from,
        &CameraTrack::Turntable {
            center,
            distance,
            elevation,
        } => center + Vec3::new(0.0, elevation.sin(), elevation.cos()) * distance,
    };
    Layout {
        instances: u.instances.clone(),
        motion: Motion::Static,
        near: u.near,
        far: u.far,
        eye,
        forward: u.forward,
        track: Some(u.camera.clone()),
        unified: Some(u.data.clone()),
    }
}

/// Builds `input.kind`'s blocks (as models), seams and DAG.
pub fn build(input: UnifiedInput<'_>) -> Result<(Vec<Model>, UnifiedParts)> {
    match input.kind {
        SceneKind::BunnyHalves => halves(input),
        _ => terrain(input),
    }
}

/// bunny-halves: two cubes side by side, meeting in the plane x = the mesh's centre; the first half always at
/// LOD0, the second always at its quarter; a turntable around the mesh's bounding sphere.
fn halves(input: UnifiedInput<'_>) -> Result<(Vec<Model>, UnifiedParts)> {
    let (lo, hi, extent) = checked_bounds(&input.mesh, input.mesh_source)?;
    let cell = extent as f64 * 1.01;
    let centre = ((lo.x + hi.x) * 0.5) as f64;
    let grid = Grid {
        origin: DVec3::new(
            centre - cell,
            lo.y as f64 - 0.005 * cell,
            lo.z as f64 - 0.005 * cell,
        ),
        cell,
        dims: [2, 1, 1],
    };
    let style = BlockStyle {
        targets: &HALVES_TARGETS,
        color: BUNNY_COLOR,
        switch_source: SwitchSource::Scene,
    };
    let mut made = prepare(&input, grid, style)?;
    let Sphere {
        centre: center,
        radius,
    } = input.mesh.bounding_sphere();
    let distance = fit_distance(radius, input.width, input.height, input.fov_y) / 0.8;
    for (bi, m) in made.blocks.models.iter_mut().enumerate() {
        // The first half never leaves LOD0, the second never shows it.
        m.switches = vec![if bi == 0 {
            distance * 1e3
        } else {
            distance * 0.05
        }];
    }
    let view = View {
        track: CameraTrack::Turntable {
            center,
            distance,
            elevation: 10f32.to_radians(),
        },
        forward: -Vec3::Z,
        near: radius * 0.02,
        far: distance + 4.0 * radius,
    };
    finish(input, made, view)
}

/// terrain: cubic blocks, `input.blocks` along the longest side, with LODs selected by projected error; a
/// flight along +z over the mesh.
fn terrain(input: UnifiedInput<'_>) -> Result<(Vec<Model>, UnifiedParts)> {
    let (lo, hi, extent) = checked_bounds(&input.mesh, input.mesh_source)?;
    let grid = Grid::covering(
        &input.mesh.positions,
        extent as f64 / input.blocks as f64 * (1.0 + 1e-6),
    )?;
    let style = BlockStyle {
        targets: &TERRAIN_TARGETS,
        color: TERRAIN_COLOR,
        switch_source: SwitchSource::PixelError,
    };
    let mut made = prepare(&input, grid, style)?;
    let pitch = 10f32.to_radians();
    let y = hi.y + 0.03 * extent;
    let x = (lo.x + hi.x) * 0.5;
    let (z0, z1) = (lo.z - 0.05 * extent, lo.z + 0.8 * (hi.z - lo.z));
    let view = View {
        track: CameraTrack::Flight(Vec3::new(x, y, z0), Vec3::new(x, y, z1)),
        forward: Vec3::new(0.0, -pitch.sin(), pitch.cos()),
        near: extent * 5e-4,
        far: extent * 2.0,
    };
    for m in &mut made.blocks.models {
        m.switches = terrain_switches(m, &input);
    }
    finish(input, made, view)
}

/// A terrain block's switch distances: where each LOD's error projects to `--pixel-error` pixels at the
/// distance from the camera to the block's bounding sphere, spread so that consecutive transition bands never
/// overlap.
fn terrain_switches(m: &Model, input: &UnifiedInput<'_>) -> Vec<f32> {
    let schedule = input.schedule;
    let band_ratio = (1.0 + schedule.band) * (1.0 + schedule.hysteresis)
        / ((1.0 - schedule.band) * (1.0 - schedule.hysteresis))
        * 1.01;
    let mut out: Vec<f32> = Vec::new();
    for lod in &m.chain.lods[1..] {
        let d = crate::geometry::projection::switch_distance(
            lod.error_abs,
            1.0,
            input.pixel_error,
            input.height,
            input.fov_y,
        ) + m.radius;
        let d = match out.last() {
            Some(&prev) if d < prev * band_ratio => prev * band_ratio,
            _ => d,
        };
        out.push(d);
    }
    out
}

/// The mesh's bounds and longest side, after checking it has an area and an extent.
fn checked_bounds(mesh: &Mesh, mesh_source: &str) -> Result<(Vec3, Vec3, f32)> {
    mesh.check_area(mesh_source)?;
    let (lo, hi) = mesh.bounds();
    let extent = (hi - lo).max_element();
    if !(extent.is_finite() && extent > 0.0) {
        return Err(Error::Mesh {
            path: mesh_source.to_string(),
            problem: "has zero extent".into(),
        });
    }
    Ok((lo, hi, extent))
}

/// What differs between the two scenes' blocks.
struct BlockStyle {
    targets: &'static [f32],
    color: [f32; 3],
    switch_source: SwitchSource,
}

/// Where the camera of a unified scene goes, and its clip planes.
struct View {
    track: CameraTrack,
    forward: Vec3,
    near: f32,
    far: f32,
}

/// A scene's blocks as the partition and the simplifier made them: models (switch distances still to set),
/// LODs and vertex normals per block.
struct Blocks {
    partition: Partition,
    chains: Vec<Vec<BlockLod>>,
    normals: Vec<Vec<[f32; 3]>>,
    models: Vec<Model>,
    targets: &'static [f32],
    bytes: u64,
    partition_ms: f64,
    lod_chains_ms: f64,
}

/// Every pair of neighbouring blocks' seams at every pair of their LODs.
struct Seams {
    seams: Vec<Seam>,
    pairs: usize,
    triangles: usize,
    bytes: u64,
    ms: f64,
}

/// The steps both scenes share before their camera: blocks, seams and the cluster DAG.
struct Prepared {
    blocks: Blocks,
    seams: Seams,
    dag: ClusterDag,
}

fn prepare(input: &UnifiedInput<'_>, grid: Grid, style: BlockStyle) -> Result<Prepared> {
    let blocks = blocks(input, grid, style)?;
    let seams = seams(&blocks);
    let dag = ClusterDag::build(input.mesh_source, &input.mesh)?;
    Ok(Prepared { blocks, seams, dag })
}

/// Partitions the mesh into `grid`'s blocks and builds each block's LOD chain and model.
fn blocks(input: &UnifiedInput<'_>, grid: Grid, style: BlockStyle) -> Result<Blocks> {
    let mesh = &input.mesh;
    let started = Instant::now();
    let partition = match input.partition {
        PartitionMode::Clip => Partition::clip(&mesh.positions, &mesh.indices, grid),
        PartitionMode::Bin => Partition::bin(&mesh.positions, &mesh.indices, grid),
    };
    let partition_ms = started.elapsed().as_secs_f64() * 1e3;
    let started = Instant::now();
    let mut chains = partition.lod_chains(style.targets)?;
    // A LOD the simplifier emptied (a sliver of a block) repeats the one before.
    for chain in &mut chains {
        for l in 1..chain.len() {
            if chain[l].indices.is_empty() {
                chain[l] = chain[l - 1].clone();
            }
        }
    }
    let normals = partition.vertex_normals(&mesh.positions, &mesh.normals, &mesh.indices);
    let mut models = Vec::with_capacity(partition.blocks.len());
    let mut bytes = 0u64;
    for (bi, chain) in chains.iter().enumerate() {
        let (model, model_bytes) =
            block_model(input.kind, &partition, bi, chain, &normals[bi], &style)?;
        bytes += model_bytes;
        models.push(model);
    }
    Ok(Blocks {
        partition,
        chains,
        normals,
        models,
        targets: style.targets,
        bytes,
        partition_ms,
        lod_chains_ms: started.elapsed().as_secs_f64() * 1e3,
    })
}

/// Block `bi`'s model (no switch distances yet) from its LODs' indices, and the bytes of its LOD meshes.
fn block_model(
    kind: SceneKind,
    partition: &Partition,
    bi: usize,
    chain: &[BlockLod],
    normals: &[[f32; 3]],
    style: &BlockStyle,
) -> Result<(Model, u64)> {
    let b = &partition.blocks[bi];
    let block_name = format!(
        "{} block {},{},{}",
        kind.name(),
        b.coord[0],
        b.coord[1],
        b.coord[2]
    );
    let full = Mesh::new(
        &block_name,
        b.positions.clone(),
        Some(normals.to_vec()),
        b.indices.clone(),
    )?;
    let lods = chain
        .iter()
        .zip(style.targets)
        .map(|(l, &f)| {
            Ok(Lod {
                mesh: crate::geometry::lod::compact(&block_name, &full, &l.indices)?,
                target_fraction: f,
                error_abs: l.error_abs,
            })
        })
        .collect::<Result<Vec<_>>>()?;
    let bytes = lods
        .iter()
        .map(|l| l.mesh.vertex_count() as u64 * VERTEX_BYTES + l.mesh.indices.len() as u64 * 4)
        .sum::<u64>();
    let Sphere {
        centre: center,
        radius,
    } = lods[0].mesh.bounding_sphere();
    let model = Model {
        name: block_name,
        color: style.color,
        lod_colors: Vec::new(),
        spin_per_frame: 0.0,
        chain: LodChain { lods },
        switches: Vec::new(),
        switch_source: style.switch_source,
        center,
        radius,
        scale: 1.0,
        deformed_reach: None,
    };
    Ok((model, bytes))
}

/// The seams of every pair of neighbouring blocks, at every pair of their LODs.
fn seams(blocks: &Blocks) -> Seams {
    let started = Instant::now();
    let pairs = blocks.partition.seam_pairs();
    let mut seams = Vec::with_capacity(pairs.len());
    let (mut triangles, mut bytes) = (0, 0u64);
    for pair in &pairs {
        let (a, b) = pair.blocks;
        let (la, lb) = (blocks.chains[a].len(), blocks.chains[b].len());
        let mut meshes = Vec::with_capacity(la * lb);
        for lod_a in &blocks.chains[a] {
            for lod_b in &blocks.chains[b] {
                let m = seam_mesh(&blocks.partition, &blocks.normals, pair, lod_a, lod_b);
                triangles += m.indices.len() / 3;
                bytes += m.positions.len() as u64 * VERTEX_BYTES + m.indices.len() as u64 * 4;
                meshes.push(m);
            }
        }
        seams.push(Seam {
            blocks: (a as u32, b as u32),
            lods: (la as u32, lb as u32),
            meshes,
        });
    }
    Seams {
        seams,
        pairs: pairs.len(),
        triangles,
        bytes,
        ms: started.elapsed().as_secs_f64() * 1e3,
    }
}

/// The scene from its prepared blocks (switch distances set) and camera: the switch distances checked, one
/// instance per block, and the preprocessing's record.
fn finish(
    input: UnifiedInput<'_>,
    made: Prepared,
    view: View,
) -> Result<(Vec<Model>, UnifiedParts)> {
    let Prepared { blocks, seams, dag } = made;
    for m in &blocks.models {
        input.schedule.check_switches(&m.name, &m.switches)?;
    }
    let mesh = input.mesh;
    let p = &blocks.partition;
    let preprocessing = Preprocessing {
        partition: p.mode,
        grid: p.grid.dims,
        block_size: p.grid.cell,
        blocks: p.blocks.len(),
        input_triangles: mesh.triangle_count(),
        block_triangles: p.triangle_count(),
        lod_targets: blocks.targets.to_vec(),
        seam_pairs: seams.pairs,
        seam_edges: p.seams.len(),
        seam_triangles_all_lod_pairs: seams.triangles,
        partition_ms: blocks.partition_ms,
        lod_chains_ms: blocks.lod_chains_ms,
        seams_ms: seams.ms,
        blocks_ms: blocks.partition_ms + blocks.lod_chains_ms + seams.ms,
        blocks_bytes: blocks.bytes,
        seams_bytes: seams.bytes,
        clusterlod_ms: dag.build_ms,
        clusterlod_bytes: dag.bytes() + mesh.vertex_count() as u64 * VERTEX_BYTES,
        clusters: dag.clusters.len(),
        cluster_groups: dag.groups.len(),
        cluster_levels: dag.levels(),
    };
    let instances = (blocks.models.iter().enumerate())
        .map(|(i, m)| Instance {
            model: i as u32,
            position: m.center,
            yaw: 0.0,
            rotation: glam::Quat::IDENTITY,
            scale: Vec3::ONE,
        })
        .collect();
    let data = Unified {
        mesh,
        dag,
        seams: seams.seams,
        pixel_error: input.pixel_error,
        preprocessing,
        terrain: input.terrain,
    };
    let parts = UnifiedParts {
        instances,
        data: Arc::new(data),
        camera: view.track,
        forward: view.forward,
        near: view.near,
        far: view.far,
    };
    Ok((blocks.models, parts))
}

/// The seam of `pair` between its blocks at LODs `a` and `b` as a mesh of its own (three vertices a
/// triangle, copied from the blocks).
fn seam_mesh(
    partition: &Partition,
    normals: &[Vec<[f32; 3]>],
    pair: &SeamPair,
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
