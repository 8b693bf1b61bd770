//! `blocks-tree`: Blow's hierarchy of blocks on the terrain ([`crate::geometry::block_tree`]): each frame the
//! tree's cut at `--pixel-error`, a node fading into its children over the `--band` around its switch distance
//! by Blow 2003a's rules (`alpha-zwrite`'s: one side opaque, the other translucent with depth writes, the draw
//! order and the depth compare swapped at the middle of the fade), and the seams between the nodes drawn
//! opaque, whatever their levels, zipped each frame from their border chains. Opaque nodes and seams first,
//! then the translucent nodes back to front by the distance of their boxes' centres.
//!
//! The shared schedule's block states are not used: the cut is this method's own selection, and lodpop's
//! counterfactual is the previous frame's cut (nodes, alphas and seams) drawn at this frame's pose
//! ([`Counterfactual::selection_changed`]). `units_drawn` counts the nodes drawn, opaque or translucent.

use super::alpha::OVER;
use super::common::{mesh_vertex_buffer, Counterfactual, FrameInput, Method};
use crate::error::{Error, Result};
use crate::geometry::block_tree::{BlockTree, Cut};
use crate::geometry::cluster_dag::CutBound;
use crate::gpu::{
    DrawList, DrawStats, InstanceBuffer, InstanceRaw, MeshPipeline, RenderTarget, SceneGpu, View,
};
use crate::scene::schedule::InstanceState;
use crate::scene::Scene;
use glam::{Mat4, Vec3};
use wgpu::util::DeviceExt;

/// One frame's selection: the cut and its seams' indices.
#[derive(Default, Clone, PartialEq)]
struct Frame {
    cut: Cut,
    seams: Vec<u32>,
}

/// The GPU side of one frame: its seam indices and its instances (0: opaque; then one per translucent node).
struct FrameBuffers {
    seams: wgpu::Buffer,
    seam_capacity: u64,
    instances: InstanceBuffer,
}

pub struct BlocksTree {
    tree: BlockTree,
    band: f32,
    pixel_error: f32,
    color: [f32; 3],
    vertex_buffer: wgpu::Buffer,
    index_buffer: wgpu::Buffer,
    less_equal: crate::gpu::MeshPipelines,
    less: crate::gpu::MeshPipelines,
    now: FrameBuffers,
    before: FrameBuffers,
    frame: Frame,
    previous: Frame,
    list: DrawList,
    order: Vec<(u32, f32, bool)>,
}

fn seam_buffer(gpu: &SceneGpu, capacity: u64, label: &str) -> wgpu::Buffer {
    gpu.device.create_buffer(&wgpu::BufferDescriptor {
        label: Some(label),
        size: capacity.max(3) * 4,
        usage: wgpu::BufferUsages::INDEX | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    })
}

impl BlocksTree {
    pub fn new(gpu: &SceneGpu, scene: &Scene) -> Result<Self> {
        let (unified, field) = scene
            .unified
            .as_ref()
            .and_then(|u| u.terrain.map(|f| (u, f)))
            .ok_or_else(|| {
                Error::Config(format!(
                    "blocks-tree needs the terrain's height-field grid (scene terrain without --mesh), not {}",
                    scene.name()
                ))
            })?;
        let mut tree = BlockTree::build(&unified.mesh, field.quads, field.blocks)?;
        let camera = scene.cut_camera(0, unified.pixel_error, CutBound::Box);
        tree.set_switches(
            camera.pixels_per_unit,
            unified.pixel_error,
            scene.schedule.band,
        );
        let vertex_buffer = mesh_vertex_buffer(gpu, &unified.mesh, "blocks-tree vertices");
        let index_buffer = gpu
            .device
            .create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("blocks-tree indices"),
                contents: bytemuck::cast_slice(&tree.indices),
                usage: wgpu::BufferUsages::INDEX,
            });
        let translucent = |label, depth_compare| {
            gpu.mesh_pipeline(&MeshPipeline {
                label,
                morph: false,
                fragment: Some("fs_translucent"),
                id_target: None,
                cull: None,
                depth_compare,
                depth_write: true,
                blend: Some(OVER),
                extra_layouts: &[],
            })
        };
        let frame_buffers = |label| {
            let capacity = 4096;
            FrameBuffers {
                seams: seam_buffer(gpu, capacity, label),
                seam_capacity: capacity,
                instances: gpu.create_instance_buffer(label, 1 + tree.nodes.len() as u32),
            }
        };
        Ok(BlocksTree {
            band: scene.schedule.band,
            pixel_error: unified.pixel_error,
            color: scene.models.first().map_or([0.7; 3], |m| m.color),
            vertex_buffer,
            index_buffer,
            less_equal: translucent(
                "blocks-tree translucent <=",
                wgpu::CompareFunction::LessEqual,
            ),
            less: translucent("blocks-tree translucent <", wgpu::CompareFunction::Less),
            now: frame_buffers("blocks-tree now"),
            before: frame_buffers("blocks-tree before"),
            frame: Frame::default(),
            previous: Frame::default(),
            list: DrawList::default(),
            order: Vec::new(),
            tree,
        })
    }

    /// Writes `before`'s or this frame's seams and instances and draws its cut into a cleared `target`.
    fn draw(
        &mut self,
        gpu: &SceneGpu,
        encoder: &mut wgpu::CommandEncoder,
        (target, view): (&RenderTarget, View),
        eye: Vec3,
        before: bool,
    ) -> DrawStats {
        let (frame, buffers) = if before {
            (&self.previous, &mut self.before)
        } else {
            (&self.frame, &mut self.now)
        };
        if frame.seams.len() as u64 > buffers.seam_capacity {
            buffers.seam_capacity = (frame.seams.len() as u64).next_power_of_two();
            buffers.seams = seam_buffer(gpu, buffers.seam_capacity, "blocks-tree seams");
        }
        if !frame.seams.is_empty() {
            gpu.queue
                .write_buffer(&buffers.seams, 0, bytemuck::cast_slice(&frame.seams));
        }
        // Translucent nodes back to front by the distance of their boxes' centres (ties by node).
        self.order.clear();
        self.order.extend(frame.cut.translucent.iter().copied());
        let nodes = &self.tree.nodes;
        let dist = |k: u32| eye.distance((nodes[k as usize].min + nodes[k as usize].max) * 0.5);
        self.order
            .sort_by(|a, b| dist(b.0).total_cmp(&dist(a.0)).then(a.0.cmp(&b.0)));
        let [r, g, b] = self.color;
        self.list.clear();
        self.list.push(
            0,
            0,
            0,
            InstanceRaw::new(&Mat4::IDENTITY, [r, g, b, 0.0], [0.0, 1.0, 0.0, 0.0]),
        );
        for &(_, alpha, _) in &self.order {
            self.list.push(
                0,
                0,
                0,
                InstanceRaw::new(&Mat4::IDENTITY, [r, g, b, 0.0], [0.0, alpha, 0.0, 0.0]),
            );
        }
        self.list.build_in_order();
        gpu.upload(&buffers.instances, &self.list);
        let mut pass = gpu.begin_clear_pass(encoder, target, view, "blocks-tree pass");
        pass.set_vertex_buffer(0, self.vertex_buffer.slice(..));
        pass.set_vertex_buffer(1, buffers.instances.buffer.slice(..));
        pass.set_index_buffer(self.index_buffer.slice(..), wgpu::IndexFormat::Uint32);
        pass.set_pipeline(gpu.opaque_pipeline.base());
        let mut stats = DrawStats {
            clusters: Some((frame.cut.opaque.len() + self.order.len()) as u64),
            ..Default::default()
        };
        let mut range = |pass: &mut wgpu::RenderPass<'_>, k: u32, instance: u32| {
            let n = &nodes[k as usize];
            pass.draw_indexed(
                n.first_index..n.first_index + n.index_count,
                0,
                instance..instance + 1,
            );
            stats.triangles += n.index_count as u64 / 3;
            stats.draw_calls += 1;
        };
        for &k in &frame.cut.opaque {
            range(&mut pass, k, 0);
        }
        for (i, &(k, _, swapped)) in self.order.iter().enumerate() {
            pass.set_pipeline(if swapped {
                self.less.base()
            } else {
                self.less_equal.base()
            });
            range(&mut pass, k, 1 + i as u32);
        }
        if !frame.seams.is_empty() {
            pass.set_pipeline(gpu.opaque_pipeline.base());
            pass.set_index_buffer(buffers.seams.slice(..), wgpu::IndexFormat::Uint32);
            pass.draw_indexed(0..frame.seams.len() as u32, 0, 0..1);
            stats.triangles += frame.seams.len() as u64 / 3;
            stats.draw_calls += 1;
        }
        stats
    }
}

impl Method for BlocksTree {
    fn encode(
        &mut self,
        gpu: &SceneGpu,
        input: &FrameInput<'_>,
        encoder: &mut wgpu::CommandEncoder,
        target: &RenderTarget,
    ) -> DrawStats {
        std::mem::swap(&mut self.frame, &mut self.previous);
        let camera = input
            .scene
            .cut_camera(input.frame, self.pixel_error, CutBound::Box);
        self.tree.cut(&camera, self.band, &mut self.frame.cut);
        self.tree
            .seams(&self.frame.cut.opaque, &mut self.frame.seams);
        self.draw(gpu, encoder, (target, input.view), camera.eye, false)
    }

    fn counterfactual(&mut self) -> Option<&mut dyn Counterfactual> {
        Some(self)
    }
}

impl Counterfactual for BlocksTree {
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
        let eye = input.scene.camera(input.frame).eye;
        self.draw(gpu, encoder, (before, input.view), eye, true);
    }
}
