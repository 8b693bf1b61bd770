//! `roam` and `roam-morph`: ROAM (Duchaineau et al. 1997; seed 002's terrain algorithm) on the `terrain`
//! scene's height field ([`crate::geometry::roam_mesh`]): the bintree triangulation carried from frame to frame,
//! split and merged each frame so that every triangle's projected wedgie thickness is at or under
//! `--pixel-error`, the triangulation's indices uploaded and drawn opaque in one draw. `roam-morph` moves each
//! vertex a split adds from the height of its edge's midpoint to its own over `--roam-morph-frames` frames
//! (Duchaineau §7's geomorphs, for splits; a merge is immediate). A frame that does not follow the frame before
//! (the walk restarting, the warm-up's jumps) is a camera cut: every morph settles.
//!
//! The shared schedule's block states are not used: the triangulation is this method's own selection, and
//! lodpop's counterfactual is the previous frame's triangulation (and its morphing vertices) drawn at this
//! frame's pose ([`Counterfactual::selection_changed`]). Each frame's splits and merges (bintree nodes) and the CPU
//! time of the update, the triangulation's walk and the morphs go to frames.csv (`splits`, `merges`,
//! `select_cpu_ms`).

use super::common::{identity_instance, Counterfactual, FrameInput, Method};
use crate::error::{Error, Result};
use crate::geometry::cluster_dag::CutBound;
use crate::geometry::roam_mesh::{Bintree, HeightField};
use crate::geometry::terrain::{height, TERRAIN_SIZE};
use crate::gpu::{DrawStats, InstanceBuffer, RenderTarget, SceneGpu, Selection, Vertex, View};
use crate::scene::schedule::InstanceState;
use crate::scene::Scene;
use glam::Vec3;
use std::time::Instant;
use wgpu::util::DeviceExt;

/// `roam-morph`'s flags.
#[derive(Debug, Clone, Copy, PartialEq, clap::Args, serde::Serialize, serde::Deserialize)]
#[serde(default, rename_all(deserialize = "kebab-case"))]
pub struct RoamOptions {
    /// roam-morph: frames over which a vertex a split adds moves from its edge's midpoint to its height.
    #[arg(long, default_value_t = 8, value_parser = clap::value_parser!(u32).range(1..),
          help_heading = crate::defaults::heading::METHODS)]
    pub roam_morph_frames: u32,
}

impl Default for RoamOptions {
    fn default() -> Self {
        crate::defaults::clap_defaults()
    }
}

/// No age, no slot.
const NO_AGE: u32 = u32::MAX;

const VERTEX_BYTES: u64 = std::mem::size_of::<Vertex>() as u64;

/// A vertex buffer: the grid's vertices, then a region for the morphing vertices of one frame.
struct Vertices {
    buffer: wgpu::Buffer,
    /// Morph slots after the grid's vertices.
    slots: u32,
}

/// What a frame drew: the triangulation's indices (morphing vertices renamed to their slots) and the
/// morphing vertices' slot contents.
#[derive(Default, Clone, PartialEq)]
struct Frame {
    indices: Vec<u32>,
    morphing: Vec<[f32; 10]>,
}

pub struct Roam {
    tree: Bintree,
    grid: Vec<Vertex>,
    morph_frames: Option<u32>,
    /// Per grid vertex, frames since the split that added it (up to the morph's frames: settled), or
    /// [`NO_AGE`] for a vertex no split of this frame adds; and the vertices that have an age.
    age: Vec<u32>,
    split_list: Vec<u32>,
    last_frame: Option<u32>,
    now: Vertices,
    before: Vertices,
    index_now: wgpu::Buffer,
    index_before: wgpu::Buffer,
    instance: InstanceBuffer,
    frame: Frame,
    previous: Frame,
    split_vertices: Vec<[u32; 3]>,
    slot_of: Vec<u32>,
}

impl Roam {
    /// `morph_frames`: None for `roam`, the frames of a morph for `roam-morph`.
    pub fn new(gpu: &SceneGpu, scene: &Scene, morph_frames: Option<u32>) -> Result<Self> {
        let field = scene
            .unified
            .as_ref()
            .and_then(|u| u.terrain)
            .ok_or_else(|| {
                Error::Config(format!(
                    "roam needs the terrain scene's height field (scene terrain without --mesh), not {}: a mesh \
                     is not a height field; run --method blocks or clusterlod on it",
                    scene.name()
                ))
            })?;
        let n = HeightField::grid_for(field.quads);
        let field = HeightField::from_fn(n, TERRAIN_SIZE, |x, z| height(field.seed, x, z));
        let normals = field.normals();
        let grid: Vec<Vertex> = (0..field.vertex_count() as u32)
            .map(|v| Vertex {
                position: field.position(v).to_array(),
                normal: normals[v as usize],
                aux: [0.0; 4],
            })
            .collect();
        let tree = Bintree::new(field);
        let max_indices = 6 * n as u64 * n as u64;
        let index = |label| {
            gpu.device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size: max_indices * 4,
                usage: wgpu::BufferUsages::INDEX | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            })
        };
        let instance = identity_instance(gpu, scene, "roam instance");
        let slots = if morph_frames.is_some() { 4096 } else { 0 };
        let n_vertices = grid.len();
        Ok(Roam {
            now: vertices(gpu, &grid, slots, "roam vertices"),
            before: vertices(gpu, &grid, slots, "roam vertices before"),
            slot_of: vec![NO_AGE; n_vertices],
            grid,
            tree,
            morph_frames,
            age: vec![NO_AGE; n_vertices],
            split_list: Vec::new(),
            last_frame: None,
            index_now: index("roam indices"),
            index_before: index("roam indices before"),
            instance,
            frame: Frame::default(),
            previous: Frame::default(),
            split_vertices: Vec::new(),
        })
    }

    /// The morphing vertices after this frame's update: a vertex a split added since the frame before starts at
    /// its edge's midpoint (age 0), the others age by a frame up to `frames` (settled; all settle on a cut),
    /// merged ones leave; then the frame's slot contents (the unsettled vertices, in the tree's order) and the
    /// indices renamed to them.
    fn morph(&mut self, frames: u32, cut: bool) {
        self.tree.split_vertices(&mut self.split_vertices);
        let aged: Vec<u32> = self
            .split_vertices
            .iter()
            .map(|&[c, _, _]| match self.age[c as usize] {
                _ if cut => frames,
                NO_AGE => 0,
                a => (a + 1).min(frames),
            })
            .collect();
        for &v in &self.split_list {
            self.age[v as usize] = NO_AGE;
        }
        self.split_list.clear();
        self.frame.morphing.clear();
        let base = self.grid.len() as u32;
        for (&[c, l, r], age) in self.split_vertices.iter().zip(aged) {
            if self.age[c as usize] != NO_AGE {
                continue; // the diamond's other triangle named it already
            }
            self.age[c as usize] = age;
            self.split_list.push(c);
            if age >= frames {
                continue;
            }
            let s = age as f32 / frames as f32;
            let (vc, vl, vr) = (
                &self.grid[c as usize],
                &self.grid[l as usize],
                &self.grid[r as usize],
            );
            let mid_y = (vl.position[1] + vr.position[1]) * 0.5;
            let mid_n = Vec3::from(vl.normal) + Vec3::from(vr.normal);
            let y = mid_y + (vc.position[1] - mid_y) * s;
            let n = mid_n.normalize().lerp(Vec3::from(vc.normal), s).normalize();
            let [px, _, pz] = vc.position;
            self.slot_of[c as usize] = base + self.frame.morphing.len() as u32;
            self.frame
                .morphing
                .push([px, y, pz, n.x, n.y, n.z, 0.0, 0.0, 0.0, 0.0]);
        }
        if self.frame.morphing.is_empty() {
            return;
        }
        for i in &mut self.frame.indices {
            let s = self.slot_of[*i as usize];
            if s != NO_AGE {
                *i = s;
            }
        }
        for &c in &self.split_list {
            self.slot_of[c as usize] = NO_AGE;
        }
    }

    /// Writes `frame` into `vertices` and `index` and draws it into a cleared `target`.
    fn draw(
        &self,
        gpu: &SceneGpu,
        encoder: &mut wgpu::CommandEncoder,
        (target, view): (&RenderTarget, View),
        before: bool,
    ) -> DrawStats {
        let (frame, vertices, index) = if before {
            (&self.previous, &self.before, &self.index_before)
        } else {
            (&self.frame, &self.now, &self.index_now)
        };
        if !frame.morphing.is_empty() {
            gpu.queue.write_buffer(
                &vertices.buffer,
                self.grid.len() as u64 * VERTEX_BYTES,
                bytemuck::cast_slice(&frame.morphing),
            );
        }
        if !frame.indices.is_empty() {
            gpu.queue
                .write_buffer(index, 0, bytemuck::cast_slice(&frame.indices));
        }
        let mut pass = gpu.begin_clear_pass(encoder, target, view, "roam pass");
        pass.set_vertex_buffer(0, vertices.buffer.slice(..));
        pass.set_vertex_buffer(1, self.instance.buffer.slice(..));
        pass.set_index_buffer(index.slice(..), wgpu::IndexFormat::Uint32);
        pass.set_pipeline(gpu.opaque_pipeline.base());
        let count = frame.indices.len() as u32;
        if count > 0 {
            pass.draw_indexed(0..count, 0, 0..1);
        }
        DrawStats {
            triangles: count as u64 / 3,
            draw_calls: (count > 0) as u32,
            clusters: Some(1),
            selection: None,
        }
    }

    /// Grows both vertex buffers' morph regions to hold `needed` slots (doubling), the grid copied again.
    fn reserve_slots(&mut self, gpu: &SceneGpu, needed: usize) {
        if needed as u32 <= self.now.slots {
            return;
        }
        let slots = (needed as u32).next_power_of_two();
        self.now = vertices(gpu, &self.grid, slots, "roam vertices");
        self.before = vertices(gpu, &self.grid, slots, "roam vertices before");
    }
}

/// A vertex buffer of `grid` and `slots` morph slots after it.
fn vertices(gpu: &SceneGpu, grid: &[Vertex], slots: u32, label: &str) -> Vertices {
    let mut contents: Vec<Vertex> = grid.to_vec();
    contents.resize(
        grid.len() + slots as usize,
        Vertex {
            position: [0.0; 3],
            normal: [0.0, 1.0, 0.0],
            aux: [0.0; 4],
        },
    );
    let buffer = gpu
        .device
        .create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some(label),
            contents: bytemuck::cast_slice(&contents),
            usage: wgpu::BufferUsages::VERTEX | wgpu::BufferUsages::COPY_DST,
        });
    Vertices { buffer, slots }
}

impl Method for Roam {
    fn encode(
        &mut self,
        gpu: &SceneGpu,
        input: &FrameInput<'_>,
        encoder: &mut wgpu::CommandEncoder,
        target: &RenderTarget,
    ) -> DrawStats {
        std::mem::swap(&mut self.frame, &mut self.previous);
        let started = Instant::now();
        let pixel_error = input.scene.unified.as_ref().map_or(1.0, |u| u.pixel_error);
        let camera = input
            .scene
            .cut_camera(input.frame, pixel_error, CutBound::Box);
        let counts = self.tree.update(&camera);
        self.tree.triangles_into(&mut self.frame.indices);
        if let Some(frames) = self.morph_frames {
            let cut = self.last_frame.map(|f| f + 1) != Some(input.frame);
            self.morph(frames, cut);
        }
        self.last_frame = Some(input.frame);
        let select_ns = started.elapsed().as_nanos() as u64;
        self.reserve_slots(gpu, self.frame.morphing.len());
        let mut stats = self.draw(gpu, encoder, (target, input.view), false);
        stats.selection = Some(Selection {
            splits: counts.splits,
            merges: counts.merges,
            cpu_ns: select_ns,
        });
        stats
    }

    fn counterfactual(&mut self) -> Option<&mut dyn Counterfactual> {
        Some(self)
    }
}

impl Counterfactual for Roam {
    fn selection_changed(&self) -> bool {
        self.frame != self.previous
    }

    fn encode_before(
        &mut self,
        gpu: &SceneGpu,
        input: &FrameInput<'_>,
        _history: &[&[InstanceState]],
        encoder: &mut wgpu::CommandEncoder,
        before: &RenderTarget,
    ) {
        self.reserve_slots(gpu, self.previous.morphing.len());
        self.draw(gpu, encoder, (before, input.view), true);
    }
}
