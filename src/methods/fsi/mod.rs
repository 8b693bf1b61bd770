//! `fsi`, `fsi-noreproject`, `fsi-sameframe`: Frame Sequential Interpolation (Scherzer and Wimmer 2008,
//! Scherzer & Wimmer 2008 sections 3.2-3.5 and 4.1), the reference implementation of this harness, and its two ablations.
//!
//! Two LOD buffers (colour, depth, instance id) are used ping-pong: frame f renders the whole scene into buffer
//! f mod 2; the other still holds frame f-1. n-instances are drawn normally with id 0. A t-instance gets id
//! `instance index + 1` and alternates between `lod_from` and `lod_to` frame by frame (section 3.2, 4.1: a
//! toggle counter per instance, started when its transition starts). The first frame of a transition shows
//! the LOD that is complete at that moment (tau = 1: `lod_from` when the transition is entered at k < 0.5,
//! `lod_to` when entered from the far end, k > 0.5), the one the previous frame showed as an n-instance;
//! starting with the barely visible other LOD would lose the object for a frame, as the older buffer then
//! holds it with id 0 (case 1 keeps the newer, empty pixel). Instances start transitions on different frames, so their toggles are out of
//! phase and the triangle count stays even between frames; the instances already in transition at a pass's
//! first frame (all of them in a static scene) get phases that balance it ([`Fsi::balance_phases`]). Each of its fragments is kept
//! by eq. 1 where `visTex(p) <= tau`, p the object-space position before animation, the texture read at
//! (p.x + p.z, p.y + p.z) (section 3.3) with one repeat per model radius (the paper leaves the scale open).
//! tau follows Fig. 2 with the schedule's shared k: the incoming LOD has tau = min(1, 2k), the outgoing one
//! tau = min(1, 2(1 - k)), so one of the two is always complete, with one addition the paper leaves open:
//! the frame-sequential variants widen the midpoint plateau by the instance's change of k since the previous
//! frame ([`tau_with_margin`]), because the older buffer holds the other LOD at the previous k. Without it, a
//! frame whose k steps across 0.5 combines two buffers with coinciding holes (measured on bunny-sweep, ci
//! profile: max pop 0.0224 without, against discrete's 0.0167). A combination pass (shaders/fsi_combine.wgsl)
//! then merges the two buffers into the frame (sections 3.4-3.5, eq. 2).
//!
//! Choices the paper leaves open, made here:
//! - t-instances are drawn two-sided, like everything else, and their back faces write an id of their own
//!   (front faces `2 i + 1`, back faces `2 i + 2` for instance i: [`front_id`], [`back_id`]). Where eq. 1
//!   discards a front fragment, the object's own inside shows there; with the front's id, case 3 would average
//!   it with the other LOD's front (dark speckle all over the object); with an id of its own, case 2 picks the
//!   other LOD's front by depth, as it would pick it over anything behind the object. Where both buffers show
//!   the inside (the camera near or inside the bounds of a mesh with holes, or inside an open one), both hold
//!   the back id and case 3 averages them, as the two-sided reference shows that inside. (Culling back faces,
//!   the earlier choice, left background there: with the camera inside the bunny, on all 19,200 pixels the
//!   reference covers at 160x120; `tests/it/scene_fidelity.rs`.)
//! - Formats: colour Rgba8UnormSrgb (4 B), depth Depth32Float (4 B, the depth attachment itself, read as a
//!   texture by the combination pass), id R16Uint (2 B; R32Uint when a scene has 32,767 instances or more, as ids go to twice the count):
//!   10 bytes per pixel per buffer against the paper's 7 (24-bit colour, 16-bit float depth, 16-bit float id),
//!   20 MiB for two 1024x1024 buffers against its 14 MB. wgpu has no 24-bit colour or 16-bit float depth
//!   attachment; Depth16Unorm would lose precision the depth test of case 2 needs.
//! - The average of case 3 is taken in linear RGB (the colour buffers are sRGB-encoded), like the blending of
//!   the alpha methods.
//! - When a frame does not follow the previous one (the first frame of a pass), no older buffer exists: the
//!   other buffer is rendered in the same frame with the other LODs and the same camera (that frame costs
//!   two scene renders, as `fsi-sameframe` always does).
//! - `fsi-noreproject` reads the older buffer at the same pixel and compares the two stored depths as they are.
//! - `fsi-sameframe` renders the whole scene into both buffers every frame (t-instances at `lod_from` in one and
//!   `lod_to` in the other, same camera) and combines without reprojection: visibility textures without frame
//!   sequencing.
//!
//! The folder by concern: `options.rs` (the variants and flags), `toggle.rs` (tau, the toggle, the ids, eq. 2's
//! reprojection: CPU arithmetic), `lod_buffer.rs` (the buffers and the pipelines that draw into them),
//! `combine_pass.rs` (the combination pass); this file holds the method: its state from frame to frame, its
//! frame, and its answers to the quality pass.

mod combine_pass;
mod lod_buffer;
mod options;
mod toggle;

pub use combine_pass::COMBINE_WGSL;
pub use lod_buffer::{id_format, lod_buffer_bytes_per_pixel, LodBufferImage};
pub use options::{FsiCheck, FsiOptions, Variant, VisSpace};
pub use toggle::{
    back_id, blend_weight, first_lod, front_id, reprojection, tau, tau_with_margin, toggle_lod,
};

use crate::effects::shadow::Caster;
use crate::error::Result;
use crate::gpu::scene_gpu::View;
use crate::gpu::timestamps::GpuTimer;
use crate::gpu::GpuContext;
use crate::gpu::{read_texture, DrawList, DrawStats, InstanceBuffer, RenderTarget, SceneGpu};
use crate::methods::common::{Counterfactual, DumpKind, FrameInput, Method};
use crate::scene::schedule::InstanceState;
use crate::scene::{Camera, Scene};
use combine_pass::{
    combination, combine_group, combine_layout, combine_pipeline, combine_program, combine_targets,
    CombineRaw,
};
use glam::Mat4;
use lod_buffer::{
    draw_pipelines, fill_list, id_bytes, visibility_group, Choice, LodBuffer, N_PIPELINE,
    T_PIPELINE,
};
use toggle::Toggle;

/// The two LOD buffers' choices the combination of one quality-pass frame used: (newer, older).
struct FrameChoices {
    frame: u32,
    newer: Vec<Choice>,
    older: Vec<Choice>,
}

/// lodpop's scratch objects, made on first use (never in a timing-only use): two LOD buffers, their
/// combination inputs with a same-pixel uniform, and instance room for four buffer renders in one submission.
struct Scratch {
    buffers: [LodBuffer; 2],
    /// Holds the same-pixel uniform (kept alive by the bind group).
    group: wgpu::BindGroup,
    /// The combination at one pose: the older buffer read at the same pixel.
    pipeline: wgpu::ComputePipeline,
    instances: InstanceBuffer,
    lists: [DrawList; 4],
}

/// A t-instance's toggle: the frame its transition started (its phase 0; may be before the pass's first frame,
/// see [`Fsi::encode`]), its (lod_from, lod_to), the LOD it started with.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Started {
    frame: i64,
    lods: (u32, u32),
    first: u32,
}

/// FSI's combination pass: the variant's pipeline (fsi_combine.wgsl's SAME_PIXEL and COMBINATION), its module
/// and layouts (for the scratch pipeline of lodpop's counterfactuals), its inputs, output and timer.
struct Combination {
    pipeline: wgpu::ComputePipeline,
    module: wgpu::ShaderModule,
    pipeline_layout: wgpu::PipelineLayout,
    layout: wgpu::BindGroupLayout,
    /// The pass writes here (storage textures cannot be sRGB); copied into the frame's target.
    output: wgpu::Texture,
    output_view: wgpu::TextureView,
    uniform: wgpu::Buffer,
    /// The pass's inputs, indexed by the newer buffer.
    groups: [wgpu::BindGroup; 2],
    timer: Option<GpuTimer>,
}

/// The state FSI keeps per instance.
struct Toggles {
    /// The frame its current transition started, its (lod_from, lod_to) and its first LOD.
    started: Vec<Option<Started>>,
    /// k of the previous frame, and this frame's |k - previous k| (the tau margin).
    previous_k: Vec<Option<f32>>,
    margin: Vec<f32>,
}

pub struct Fsi {
    variant: Variant,
    buffers: [LodBuffer; 2],
    lists: [DrawList; 2],
    instances: InstanceBuffer,
    n_pipeline: crate::gpu::MeshPipelines,
    t_pipeline: crate::gpu::MeshPipelines,
    vis_group: wgpu::BindGroup,
    /// The combination pass: the two LOD buffers into the frame.
    combine: Combination,
    /// Per instance: its toggle and its k's step.
    toggles: Toggles,
    /// The frame and camera the newer buffer of the last frame was rendered with.
    previous: Option<(u32, Camera)>,
    /// What each LOD buffer drew last (per buffer), and the last two quality-pass frames' choices.
    choices: [Vec<Choice>; 2],
    /// The LOD buffer the last `encode` rendered at its frame's pose (its newer).
    last_newer: usize,
    recent: std::collections::VecDeque<FrameChoices>,
    scratch: Option<Scratch>,
    /// Texture repeats per object-space unit, per model (1 / object-space radius).
    repeats_per_unit: Vec<f32>,
    id_format: wgpu::TextureFormat,
}

impl Fsi {
    pub fn new(
        gpu: &SceneGpu,
        scene: &Scene,
        options: &FsiOptions,
        seed: u64,
        variant: Variant,
    ) -> Self {
        let device = &gpu.device;
        let (w, h) = (scene.width, scene.height);
        let format = id_format(scene.instances.len());
        let buffers = [
            LodBuffer::new(gpu, "fsi LOD buffer 0", w, h, format),
            LodBuffer::new(gpu, "fsi LOD buffer 1", w, h, format),
        ];
        let (vis_layout, vis_group) = visibility_group(gpu, options.vis_texture, seed);
        let (n_pipeline, t_pipeline) = draw_pipelines(gpu, options, variant, format, &vis_layout);
        let combine_layout = combine_layout(device);
        let (module, layout) = combine_program(device, &combine_layout);
        let forward_check =
            variant == Variant::Sequential && options.fsi_check == FsiCheck::Forward;
        let combine_pipeline = combine_pipeline(
            device,
            (&module, &layout),
            !matches!(variant, Variant::Sequential | Variant::Blend),
            combination(variant, forward_check),
        );
        let (combined, combined_view, combine_uniform) = combine_targets(device, w, h);
        let combine_groups = [0, 1].map(|newer| {
            combine_group(
                device,
                &combine_layout,
                &buffers,
                newer,
                &combine_uniform,
                &combined_view,
            )
        });
        Fsi {
            variant,
            buffers,
            lists: [DrawList::default(), DrawList::default()],
            instances: gpu
                .create_instance_buffer("fsi instances", 2 * scene.instances.len() as u32),
            n_pipeline,
            t_pipeline,
            vis_group,
            combine: Combination {
                pipeline: combine_pipeline,
                module,
                pipeline_layout: layout,
                layout: combine_layout,
                output: combined,
                output_view: combined_view,
                uniform: combine_uniform,
                groups: combine_groups,
                timer: GpuTimer::on_device(device, gpu.queue.get_timestamp_period(), scene.frames),
            },
            toggles: Toggles {
                started: vec![None; scene.instances.len()],
                previous_k: vec![None; scene.instances.len()],
                margin: vec![0.0; scene.instances.len()],
            },
            previous: None,
            repeats_per_unit: scene
                .models
                .iter()
                .map(|m| m.scale / m.radius.max(f32::MIN_POSITIVE))
                .collect(),
            id_format: format,
            last_newer: 0,
            choices: [Vec::new(), Vec::new()],
            recent: std::collections::VecDeque::new(),
            scratch: None,
        }
    }

    /// At a pass's first frame: sets the toggle phase of the instances already in transition so that the
    /// triangle count stays even between frames (section 4.1). A transition that starts mid-pass starts at
    /// phase 0, its first frame showing the LOD that is complete, the one the older buffer holds as an
    /// n-instance. At a pass's first frame both buffers are rendered now, so either phase is right, and
    /// starting them all at phase 0 would toggle them in step (every instance of a static scene). Greedy:
    /// largest triangle difference first, each instance given the phase that brings the running difference
    /// between this frame and the next closest to zero.
    fn balance_phases(&mut self, scene: &Scene, f: u32) {
        let tris = |model: u32, lod: u32| -> i64 {
            scene.models[model as usize]
                .chain
                .lods
                .get(lod as usize)
                .map_or(0, |l| l.mesh.triangle_count() as i64)
        };
        let mut diffs: Vec<(usize, i64)> = self
            .toggles
            .started
            .iter()
            .enumerate()
            .filter_map(|(i, st)| {
                let Started {
                    lods: (from, to),
                    first,
                    ..
                } = (*st)?;
                let other = if first == from { to } else { from };
                let model = scene.instances[i].model;
                Some((i, tris(model, first) - tris(model, other)))
            })
            .collect();
        diffs.sort_by_key(|&(i, d)| (std::cmp::Reverse(d.abs()), i));
        let mut balance = 0i64;
        for (i, d) in diffs {
            if let Some(st) = self.toggles.started[i].as_mut() {
                if balance.signum() * d.signum() > 0 {
                    // Phase 1: the other LOD now, the first one next frame.
                    st.frame = f as i64 - 1;
                    balance -= d;
                } else {
                    balance += d;
                }
            }
        }
    }

    /// Fills list `slot` with the scene as LOD buffer `parity` shows it and uploads it to its half of the
    /// instance buffer.
    fn prepare(&mut self, gpu: &SceneGpu, input: &FrameInput<'_>, slot: usize, toggle: Toggle) {
        let choices = &mut self.choices[slot];
        choices.clear();
        for (i, (inst, s)) in input.scene.instances.iter().zip(input.states).enumerate() {
            choices.push(if s.in_transition() {
                let lod = match (toggle, self.toggles.started[i]) {
                    (Toggle::Buffer(0), _) => s.lod_from,
                    (Toggle::Buffer(_), _) => s.lod_to,
                    (Toggle::AtFrame(f), Some(st)) => toggle_lod(s, st.first, f as i64 - st.frame),
                    (Toggle::AtFrame(_), None) => first_lod(s),
                };
                Choice {
                    pipeline: T_PIPELINE,
                    model: inst.model,
                    lod,
                    params: [
                        self.repeats_per_unit[inst.model as usize],
                        if self.variant == Variant::Blend {
                            blend_weight(s, lod)
                        } else {
                            tau_with_margin(s, lod, self.toggles.margin[i])
                        },
                        lod as f32,
                        front_id(i) as f32,
                    ],
                }
            } else {
                let lod = s.lod_from;
                Choice {
                    pipeline: N_PIPELINE,
                    model: inst.model,
                    lod,
                    params: [0.0, 1.0, lod as f32, 0.0],
                }
            });
        }
        fill_list(&mut self.lists[slot], input, choices);
        gpu.upload_at(
            &self.instances,
            slot as u32 * input.scene.instances.len() as u32,
            &self.lists[slot],
        );
    }

    fn render(
        &self,
        (gpu, view): (&SceneGpu, View),
        encoder: &mut wgpu::CommandEncoder,
        slot: usize,
        buffer: usize,
        instances: u32,
    ) -> DrawStats {
        self.render_into(
            (gpu, view),
            encoder,
            &self.buffers[buffer],
            &self.lists[slot],
            &self.instances,
            slot as u32 * instances,
        )
    }

    /// Draws `list` (uploaded to `instances` from `first` on) into LOD buffer `b`, cleared first, lit by the
    /// view's shadow map (its scissor is for the frame's own target, not the LOD buffers).
    fn render_into(
        &self,
        (gpu, view): (&SceneGpu, View),
        encoder: &mut wgpu::CommandEncoder,
        b: &LodBuffer,
        list: &DrawList,
        instances: &InstanceBuffer,
        first: u32,
    ) -> DrawStats {
        let [r, g, bl] = crate::scene::BACKGROUND;
        let mut pass = gpu.counted(
            view,
            encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("fsi LOD buffer pass"),
                color_attachments: &[
                    Some(wgpu::RenderPassColorAttachment {
                        view: &b.target.color_view,
                        depth_slice: None,
                        resolve_target: None,
                        ops: wgpu::Operations {
                            load: wgpu::LoadOp::Clear(wgpu::Color {
                                r: r as f64,
                                g: g as f64,
                                b: bl as f64,
                                a: 1.0,
                            }),
                            store: wgpu::StoreOp::Store,
                        },
                    }),
                    Some(wgpu::RenderPassColorAttachment {
                        view: &b.id_view,
                        depth_slice: None,
                        resolve_target: None,
                        ops: wgpu::Operations {
                            load: wgpu::LoadOp::Clear(wgpu::Color::TRANSPARENT),
                            store: wgpu::StoreOp::Store,
                        },
                    }),
                ],
                depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                    view: &b.target.depth_view,
                    depth_ops: Some(wgpu::Operations {
                        load: wgpu::LoadOp::Clear(1.0),
                        store: wgpu::StoreOp::Store,
                    }),
                    stencil_ops: None,
                }),
                timestamp_writes: None,
                occlusion_query_set: None,
                multiview_mask: None,
            }),
        );
        pass.set_bind_group(0, gpu.camera_group(view.shadow), &[]);
        pass.set_bind_group(1, &self.vis_group, &[]);
        gpu.draw(
            &mut pass,
            instances,
            first,
            list,
            &[&self.n_pipeline, &self.t_pipeline],
        )
    }
}

impl Fsi {
    /// The combination pass over the LOD buffers of `group`, into `target`, by `pipeline`.
    fn combine(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        (pipeline, group): (&wgpu::ComputePipeline, &wgpu::BindGroup),
        target: &RenderTarget,
    ) {
        {
            let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("fsi combine pass"),
                timestamp_writes: None,
            });
            pass.set_pipeline(pipeline);
            pass.set_bind_group(0, group, &[]);
            pass.dispatch_workgroups(target.width.div_ceil(8), target.height.div_ceil(8), 1);
        }
        // Same bytes, sRGB-tagged: copies between the two formats are plain copies.
        encoder.copy_texture_to_texture(
            self.combine.output.as_image_copy(),
            target.color.as_image_copy(),
            self.combine.output.size(),
        );
    }

    /// The scratch objects of lodpop's counterfactuals, made on first use.
    fn scratch(&mut self, gpu: &SceneGpu, scene: &Scene) -> &Scratch {
        let (w, h) = (scene.width, scene.height);
        let n = scene.instances.len() as u32;
        // Both buffers at one pose: no reprojection, no forward check (fsi-sameframe's combination), fsi-blend's
        // blending.
        let combination = combination(self.variant, false);
        let (device, layout, view, format) = (
            &gpu.device,
            &self.combine.layout,
            &self.combine.output_view,
            self.id_format,
        );
        let module = (&self.combine.module, &self.combine.pipeline_layout);
        self.scratch.get_or_insert_with(|| {
            let buffers = [
                LodBuffer::new(gpu, "fsi lodpop buffer 0", w, h, format),
                LodBuffer::new(gpu, "fsi lodpop buffer 1", w, h, format),
            ];
            let uniform = device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("fsi lodpop combine uniform"),
                size: std::mem::size_of::<CombineRaw>() as u64,
                usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            });
            let raw = CombineRaw {
                reproject: Mat4::IDENTITY.to_cols_array_2d(),
                forward: Mat4::IDENTITY.to_cols_array_2d(),
                size: [w as f32, h as f32, 0.0, 0.0],
            };
            gpu.queue
                .write_buffer(&uniform, 0, bytemuck::bytes_of(&raw));
            Scratch {
                group: combine_group(device, layout, &buffers, 0, &uniform, view),
                pipeline: combine_pipeline(device, module, true, combination),
                buffers,
                instances: InstanceBuffer::new(device, "fsi lodpop instances", 4 * n),
                lists: Default::default(),
            }
        })
    }

    /// Draws the combination that `choices` describes with both LOD buffers at `input`'s pose into `target`,
    /// using scratch lists `2 * half` and `2 * half + 1`.
    fn encode_at_pose(
        &mut self,
        gpu: &SceneGpu,
        input: &FrameInput<'_>,
        choices: (&[Choice], &[Choice]),
        half: usize,
        encoder: &mut wgpu::CommandEncoder,
        target: &RenderTarget,
    ) {
        self.scratch(gpu, input.scene);
        let Some(mut scratch) = self.scratch.take() else {
            return;
        };
        let n = input.scene.instances.len() as u32;
        for (k, c) in [choices.0, choices.1].into_iter().enumerate() {
            let slot = 2 * half + k;
            let list = &mut scratch.lists[slot];
            fill_list(list, input, c);
            gpu.upload_at(&scratch.instances, slot as u32 * n, list);
            self.render_into(
                (gpu, input.view),
                encoder,
                &scratch.buffers[k],
                list,
                &scratch.instances,
                slot as u32 * n,
            );
        }
        self.combine(encoder, (&scratch.pipeline, &scratch.group), target);
        self.scratch = Some(scratch);
    }

    /// The recorded choices of `frame`'s combination.
    fn choices_of(&self, frame: u32) -> Option<&FrameChoices> {
        self.recent.iter().find(|c| c.frame == frame)
    }

    /// Reads both LOD buffers back (colour, depth, id), after the frames that wrote them were submitted.
    pub fn read_lod_buffers(&self, ctx: &GpuContext) -> Result<[LodBufferImage; 2]> {
        let read = |b: &LodBuffer| -> Result<LodBufferImage> {
            let color = read_texture(ctx, &b.target.color, wgpu::TextureAspect::All, 4)?;
            let depth = read_texture(ctx, &b.target.depth, wgpu::TextureAspect::DepthOnly, 4)?;
            let id_bytes = id_bytes(self.id_format);
            let ids = read_texture(ctx, &b.id, wgpu::TextureAspect::All, id_bytes)?;
            Ok(LodBufferImage {
                width: b.target.width,
                height: b.target.height,
                color,
                depth: bytemuck::pod_collect_to_vec(&depth),
                id: if id_bytes == 2 {
                    ids.chunks_exact(2)
                        .map(|c| u16::from_le_bytes([c[0], c[1]]) as u32)
                        .collect()
                } else {
                    bytemuck::pod_collect_to_vec(&ids)
                },
            })
        };
        Ok([read(&self.buffers[0])?, read(&self.buffers[1])?])
    }
}

impl Method for Fsi {
    /// The LODs of the LOD buffer rendered this frame (the older buffer's, from when it was rendered, for
    /// lodpop's counterfactual of the previous schedule): each buffer is lit by the shadow of its own LODs.
    fn shadow_caster(&self, states: &[InstanceState], i: usize, before: bool) -> Caster {
        let slot = if before {
            1 - self.last_newer
        } else {
            self.last_newer
        };
        match self.choices[slot].get(i) {
            Some(c) => Caster::Lod(c.lod),
            None => states[i].blended_caster(),
        }
    }

    /// The frame just drawn becomes the previous one of the same frame number, so that frame follows it: its
    /// older LOD buffer (rendered at that frame's pose, the same LODs) is reused and only the newer one is
    /// rendered.
    fn replay_as_previous(&mut self) {
        if let Some((f, camera)) = self.previous {
            self.previous = Some((f.wrapping_sub(1), camera));
        }
    }

    fn encode(
        &mut self,
        gpu: &SceneGpu,
        input: &FrameInput<'_>,
        encoder: &mut wgpu::CommandEncoder,
        target: &RenderTarget,
    ) -> DrawStats {
        let f = input.frame;
        let n = input.scene.instances.len() as u32;
        let camera = input.scene.camera(f);
        let newer = (f % 2) as usize;
        let follows = matches!(self.previous, Some((p, _)) if p.wrapping_add(1) == f);
        let mut stats = DrawStats::default();
        if !follows {
            self.toggles.started.fill(None);
            self.toggles.previous_k.fill(None);
        }
        let sequential = self.variant != Variant::SameFrame;
        for (i, s) in input.states.iter().enumerate() {
            let k = s.in_transition().then_some(s.k);
            self.toggles.margin[i] = match (k, self.toggles.previous_k[i]) {
                (Some(k), Some(p)) if sequential => (k - p).abs(),
                _ => 0.0,
            };
            self.toggles.previous_k[i] = k;
        }
        for (i, s) in input.states.iter().enumerate() {
            self.toggles.started[i] = match self.toggles.started[i] {
                _ if !s.in_transition() => None,
                Some(st) if st.lods == (s.lod_from, s.lod_to) => Some(st),
                _ => Some(Started {
                    frame: f as i64,
                    lods: (s.lod_from, s.lod_to),
                    first: first_lod(s),
                }),
            };
        }
        if !follows {
            self.balance_phases(input.scene, f);
        }
        let (old_toggle, new_toggle) = match self.variant {
            Variant::SameFrame => (
                Toggle::Buffer(1 - newer as u32),
                Toggle::Buffer(newer as u32),
            ),
            _ => (Toggle::AtFrame(f.wrapping_sub(1)), Toggle::AtFrame(f)),
        };
        let old_camera = match (self.variant, follows, self.previous) {
            (Variant::SameFrame, _, _) | (_, false, _) | (_, true, None) => {
                // Both buffers this frame, same camera (at a path's start: the previous frame as it would
                // have been, the other LOD of each t-instance).
                self.prepare(gpu, input, 1 - newer, old_toggle);
                stats += self.render((gpu, input.view), encoder, 1 - newer, 1 - newer, n);
                camera
            }
            (_, true, Some((_, c))) => c,
        };
        self.prepare(gpu, input, newer, new_toggle);
        stats += self.render((gpu, input.view), encoder, newer, newer, n);
        self.last_newer = newer;
        self.previous = Some((f, camera));
        if !input.timed {
            // The quality pass keeps what the combination used, for lodpop's counterfactuals.
            if self.recent.len() == 2 {
                self.recent.pop_front();
            }
            self.recent.push_back(FrameChoices {
                frame: f,
                newer: self.choices[newer].clone(),
                older: self.choices[1 - newer].clone(),
            });
        }

        let raw = CombineRaw {
            reproject: reprojection(&camera, &old_camera).to_cols_array_2d(),
            forward: reprojection(&old_camera, &camera).to_cols_array_2d(),
            size: [target.width as f32, target.height as f32, 0.0, 0.0],
        };
        gpu.queue
            .write_buffer(&self.combine.uniform, 0, bytemuck::bytes_of(&raw));
        // Timed in the quality pass only: the timing pass's frames hold nothing but the method's own work.
        let timer = self.combine.timer.as_ref().filter(|_| !input.timed);
        if let Some(t) = timer {
            t.begin(encoder, f);
        }
        self.combine(
            encoder,
            (&self.combine.pipeline, &self.combine.groups[newer]),
            target,
        );
        if let Some(t) = timer {
            t.end(encoder, f);
        }
        stats
    }

    fn extra_target_bytes(&self) -> u64 {
        let px = self.buffers[0].target.width as u64 * self.buffers[0].target.height as u64;
        2 * px * (8 + id_bytes(self.id_format) as u64)
    }

    fn stage_gpu_ms(&self, ctx: &GpuContext) -> Result<Option<Vec<Option<f64>>>> {
        match &self.combine.timer {
            Some(t) => Ok(Some(t.read(ctx)?)),
            None => Ok(None),
        }
    }

    fn debug_targets(&self) -> Vec<(DumpKind, &RenderTarget)> {
        vec![
            (DumpKind::LodBuffer0, &self.buffers[0].target),
            (DumpKind::LodBuffer1, &self.buffers[1].target),
        ]
    }

    fn counterfactual(&mut self) -> Option<&mut dyn Counterfactual> {
        Some(self)
    }
}

impl Counterfactual for Fsi {
    /// X_t: this frame's combination with both LOD buffers drawn at this frame's pose (the newer buffer's
    /// choices of t, the older buffer's of t-1): the frame without FSI's one-frame lag.
    fn encode_unlagged(
        &mut self,
        gpu: &SceneGpu,
        input: &FrameInput<'_>,
        encoder: &mut wgpu::CommandEncoder,
        now: &RenderTarget,
    ) -> bool {
        let Some(c) = self.choices_of(input.frame) else {
            return false;
        };
        let (newer, older) = (c.newer.clone(), c.older.clone());
        self.encode_at_pose(gpu, input, (&newer, &older), 0, encoder, now);
        true
    }

    /// X'_(t-1): frame t-1's combination (its newer buffer's choices of t-1, its older buffer's of t-2) with
    /// both buffers drawn at this frame's pose. lodpop = RMS(X_t - X'_(t-1)).
    fn encode_before(
        &mut self,
        gpu: &SceneGpu,
        input: &FrameInput<'_>,
        _history: &[&[InstanceState]],
        encoder: &mut wgpu::CommandEncoder,
        before: &RenderTarget,
    ) {
        let previous = input.frame.checked_sub(1).and_then(|p| self.choices_of(p));
        let Some(c) = previous.or_else(|| self.choices_of(input.frame)) else {
            return;
        };
        let (newer, older) = (c.newer.clone(), c.older.clone());
        self.encode_at_pose(gpu, input, (&newer, &older), 1, encoder, before);
    }

    fn lodpop_history(&self) -> usize {
        2
    }
}
