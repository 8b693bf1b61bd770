//! `clusterlod`: the Nanite-style cluster DAG of meshoptimizer 1.x (`meshopt::clod_build`) on a unified
//! scene's whole mesh, with the per-frame cut at `--pixel-error` ([`crate::geometry::cluster_dag`]). Clusters are drawn
//! where the cut selects them, opaque; a cut change is a hard switch. The shared schedule's block states are
//! not used: the cut is this method's own selection, and lodpop's counterfactual is the previous frame's cut
//! drawn at this frame's pose ([`Counterfactual::selection_changed`]).

use super::common::{identity_instance, mesh_vertex_buffer, Counterfactual, FrameInput, Method};
use crate::error::{Error, Result};
use crate::geometry::cluster_dag::{CutBound, CutCamera};
use crate::gpu::{DrawStats, InstanceBuffer, RenderTarget, SceneGpu, View};
use crate::scene::schedule::InstanceState;
use crate::scene::unified::Unified;
use crate::scene::Scene;
use std::sync::Arc;
use wgpu::util::DeviceExt;

/// `clusterlod`'s flags.
#[derive(Debug, Clone, Copy, PartialEq, clap::Args, serde::Serialize, serde::Deserialize)]
#[serde(default, rename_all(deserialize = "kebab-case"))]
pub struct ClusterLodOptions {
    /// clusterlod: what a group's distance to the camera is measured to: its sphere or its box.
    #[arg(long, value_enum, value_parser = crate::defaults::names_only::<CutBound>(),
          default_value_t = CutBound::Sphere, help_heading = crate::defaults::heading::METHODS)]
    pub cluster_bound: CutBound,
}

impl Default for ClusterLodOptions {
    fn default() -> Self {
        crate::defaults::clap_defaults()
    }
}

pub struct ClusterLod {
    unified: Arc<Unified>,
    bound: CutBound,
    vertex_buffer: wgpu::Buffer,
    index_buffer: wgpu::Buffer,
    instance: InstanceBuffer,
    /// This frame's cut and the previous frame's, in cluster order.
    cut: Vec<u32>,
    previous: Vec<u32>,
    over: Vec<bool>,
}

impl ClusterLod {
    pub fn new(gpu: &SceneGpu, scene: &Scene, options: &ClusterLodOptions) -> Result<Self> {
        let unified = scene.unified.clone().ok_or_else(|| {
            Error::Config(format!(
                "clusterlod needs a scene of one large mesh (bunny-halves, terrain), not {}",
                scene.name()
            ))
        })?;
        let vertex_buffer = mesh_vertex_buffer(gpu, &unified.mesh, "clusterlod vertices");
        let index_buffer = gpu
            .device
            .create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("clusterlod indices"),
                contents: bytemuck::cast_slice(&unified.dag.indices),
                usage: wgpu::BufferUsages::INDEX,
            });
        let instance = identity_instance(gpu, scene, "clusterlod instance");
        Ok(ClusterLod {
            unified,
            bound: options.cluster_bound,
            vertex_buffer,
            index_buffer,
            instance,
            cut: Vec::new(),
            previous: Vec::new(),
            over: Vec::new(),
        })
    }

    /// Draws the clusters of `cut` (cluster order) into a cleared `target`, one draw per run of consecutive
    /// clusters (their indices are contiguous).
    fn draw(
        &self,
        gpu: &SceneGpu,
        encoder: &mut wgpu::CommandEncoder,
        (target, view): (&RenderTarget, View),
        cut: &[u32],
    ) -> DrawStats {
        let dag = &self.unified.dag;
        let mut pass = gpu.begin_clear_pass(encoder, target, view, "clusterlod pass");
        pass.set_vertex_buffer(0, self.vertex_buffer.slice(..));
        pass.set_vertex_buffer(1, self.instance.buffer.slice(..));
        pass.set_index_buffer(self.index_buffer.slice(..), wgpu::IndexFormat::Uint32);
        pass.set_pipeline(gpu.opaque_pipeline.base());
        let mut stats = DrawStats {
            clusters: Some(cut.len() as u64),
            ..Default::default()
        };
        let mut i = 0;
        while i < cut.len() {
            let first = dag.clusters[cut[i] as usize];
            let (start, mut end) = (first.first_index, first.first_index + first.index_count);
            let mut j = i + 1;
            while j < cut.len() && cut[j] == cut[j - 1] + 1 {
                let c = dag.clusters[cut[j] as usize];
                end = c.first_index + c.index_count;
                j += 1;
            }
            pass.draw_indexed(start..end, 0, 0..1);
            stats.triangles += (end - start) as u64 / 3;
            stats.draw_calls += 1;
            i = j;
        }
        stats
    }

    fn camera(&self, input: &FrameInput<'_>) -> CutCamera {
        input
            .scene
            .cut_camera(input.frame, self.unified.pixel_error, self.bound)
    }
}

impl Method for ClusterLod {
    fn encode(
        &mut self,
        gpu: &SceneGpu,
        input: &FrameInput<'_>,
        encoder: &mut wgpu::CommandEncoder,
        target: &RenderTarget,
    ) -> DrawStats {
        std::mem::swap(&mut self.cut, &mut self.previous);
        let camera = self.camera(input);
        self.unified
            .dag
            .cut_into(&camera, &mut self.over, &mut self.cut);
        let cut = std::mem::take(&mut self.cut);
        let stats = self.draw(gpu, encoder, (target, input.view), &cut);
        self.cut = cut;
        stats
    }

    fn counterfactual(&mut self) -> Option<&mut dyn Counterfactual> {
        Some(self)
    }
}

impl Counterfactual for ClusterLod {
    fn selection_changed(&self) -> bool {
        self.cut != self.previous
    }

    fn encode_before(
        &mut self,
        gpu: &SceneGpu,
        input: &FrameInput<'_>,
        _history: &[&[InstanceState]],
        encoder: &mut wgpu::CommandEncoder,
        before: &RenderTarget,
    ) {
        let previous = std::mem::take(&mut self.previous);
        self.draw(gpu, encoder, (before, input.view), &previous);
        self.previous = previous;
    }
}
