//! `dither`: noise blending (Sheliemietiev et al. 2023 section 9, eq. 3). Both LODs of a t-instance are drawn opaque, with
//! fragment discard: a pixel keeps the incoming LOD (`lod_to`) where k > noise(x, y) and the outgoing LOD
//! (`lod_from`) elsewhere. The two tests are complementary, so each pixel of the overlap shows exactly one of
//! them, and depth writes stay on: no sorting, no translucency. The threshold pattern is `--noise`
//! (`src/methods/noise.rs`), tiled in screen space.
//!
//! `dither-skip` (Sheliemietiev et al. 2023 section 9, Fig. 3: "at certain thresholds only one model needs
//! drawing") draws a t-instance's LOD only where the pattern can give it a pixel: the incoming LOD keeps a pixel
//! where k > t, so none while k <= the pattern's smallest threshold; the outgoing keeps one where k <= t, so
//! none while k > its largest. The image is dither's, byte for byte; only the skipped draws go.

use super::common::{instance_raw, Counterfactual, FrameInput, Method};
use crate::gpu::{DrawList, DrawStats, InstanceBuffer, MeshPipeline, RenderTarget, SceneGpu};
use crate::methods::noise::threshold_texture;
use crate::methods::noise::NoisePattern;
use crate::scene::schedule::InstanceState;
use crate::scene::Scene;

/// `dither`'s flags.
#[derive(Debug, Clone, Copy, PartialEq, clap::Args, serde::Serialize, serde::Deserialize)]
#[serde(default, rename_all(deserialize = "kebab-case"))]
pub struct DitherOptions {
    /// dither: the threshold pattern of noise blending.
    #[arg(long, value_enum, value_parser = crate::defaults::names_only::<NoisePattern>(),
          default_value_t = NoisePattern::White16, help_heading = crate::defaults::heading::METHODS)]
    pub noise: NoisePattern,
    /// dither: move the pattern every frame, as engines do under TAA (default: a fixed pattern).
    #[arg(long, help_heading = crate::defaults::heading::METHODS)]
    pub noise_temporal: bool,
}

impl Default for DitherOptions {
    fn default() -> Self {
        crate::defaults::clap_defaults()
    }
}

const STEADY: u8 = 0;
const DITHERED: u8 = 1;
const ROLE_OUTGOING: f32 = 0.0;
const ROLE_INCOMING: f32 = 1.0;

pub struct Dither {
    list: DrawList,
    buffer: InstanceBuffer,
    steady: crate::gpu::MeshPipelines,
    dithered: crate::gpu::MeshPipelines,
    noise_group: wgpu::BindGroup,
    params: wgpu::Buffer,
    /// `--noise-temporal`: the tile size (0: ign), whose pattern moves every frame.
    temporal: Option<u32>,
    /// lodpop's counterfactual: the frame whose pattern phase to draw instead of the input's (t-1).
    pattern_frame: Option<u32>,
    /// `dither-skip`: the pattern's smallest and largest threshold (a LOD with no pixel at this k is not drawn).
    skip: Option<(f32, f32)>,
}

/// The smallest and the largest threshold `fs_dither` can compare k with: the texture's values, or for
/// interleaved gradient noise (computed in the shader, a `fract`) 0 and the largest f32 below 1.
fn threshold_bounds(values: Option<&[f32]>) -> (f32, f32) {
    match values {
        Some(v) => v
            .iter()
            .fold((f32::INFINITY, f32::NEG_INFINITY), |(lo, hi), &t| {
                (lo.min(t), hi.max(t))
            }),
        None => (0.0, 1.0 - f32::EPSILON / 2.0),
    }
}

impl Dither {
    /// `skip`: `dither-skip` (the LODs the pattern gives no pixel are not drawn).
    pub fn new(
        gpu: &SceneGpu,
        scene: &Scene,
        options: &DitherOptions,
        seed: u64,
        skip: bool,
    ) -> Self {
        let device = &gpu.device;
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("dither noise layout"),
            entries: &[
                wgpu::BindGroupLayoutEntry {
                    binding: 0,
                    visibility: wgpu::ShaderStages::FRAGMENT,
                    ty: wgpu::BindingType::Texture {
                        sample_type: wgpu::TextureSampleType::Float { filterable: false },
                        view_dimension: wgpu::TextureViewDimension::D2,
                        multisampled: false,
                    },
                    count: None,
                },
                wgpu::BindGroupLayoutEntry {
                    binding: 1,
                    visibility: wgpu::ShaderStages::FRAGMENT,
                    ty: wgpu::BindingType::Buffer {
                        ty: wgpu::BufferBindingType::Uniform,
                        has_dynamic_offset: false,
                        min_binding_size: None,
                    },
                    count: None,
                },
            ],
        });
        // Interleaved gradient noise needs no texture: a 1x1 placeholder keeps the layout the same.
        let pattern = threshold_texture(options.noise, seed);
        let skip = skip.then(|| threshold_bounds(pattern.as_ref().map(|(_, v)| v.as_slice())));
        let (size, values) = pattern.unwrap_or((0, vec![0.5]));
        let side = size.max(1);
        let texture = gpu.create_value_texture("dither thresholds", side, &values);
        let params = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("dither params"),
            size: 16,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        gpu.queue
            .write_buffer(&params, 0, bytemuck::cast_slice(&[size, 0u32, 0, 0]));
        let temporal = options.noise_temporal.then_some(size);
        let view = texture.create_view(&Default::default());
        let noise_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("dither noise"),
            layout: &layout,
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: wgpu::BindingResource::TextureView(&view),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: params.as_entire_binding(),
                },
            ],
        });
        let pipeline = |label, fragment| {
            gpu.mesh_pipeline(&MeshPipeline {
                label,
                morph: false,
                fragment: Some(fragment),
                id_target: None,
                cull: None,
                depth_compare: wgpu::CompareFunction::Less,
                depth_write: true,
                blend: None,
                extra_layouts: &[&layout],
            })
        };
        Dither {
            list: DrawList::default(),
            buffer: gpu
                .create_instance_buffer("dither instances", 2 * scene.instances.len() as u32),
            steady: pipeline("dither steady", "fs_opaque"),
            dithered: pipeline("dither dithered", "fs_dither"),
            noise_group,
            params,
            temporal,
            pattern_frame: None,
            skip,
        }
    }
}

/// The pattern's offset on `frame` with `--noise-temporal`, in pixels: for a tile of `size` (0: ign).
pub fn temporal_offset(size: u32, frame: u32) -> [f32; 2] {
    if size == 0 {
        let d = 5.588238 * (frame % 64) as f32;
        return [d, d];
    }
    let i = frame % 16 + 1;
    let s = size as f32;
    [
        (crate::effects::taa::halton(i, 2) * s).floor(),
        (crate::effects::taa::halton(i, 3) * s).floor(),
    ]
}

impl Method for Dither {
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
                // Whether the pattern gives the incoming (k > t for some t) and the outgoing (k <= t for some t)
                // LOD a pixel; without dither-skip both are drawn.
                let (incoming, outgoing) = match self.skip {
                    Some((lo, hi)) => (s.k > lo, s.k <= hi),
                    None => (true, true),
                };
                if incoming {
                    self.list.push(
                        DITHERED,
                        inst.model,
                        s.lod_to,
                        instance_raw(input, i, s.k, ROLE_INCOMING, s.lod_to),
                    );
                }
                if outgoing {
                    self.list.push(
                        DITHERED,
                        inst.model,
                        s.lod_from,
                        instance_raw(input, i, s.k, ROLE_OUTGOING, s.lod_from),
                    );
                }
            } else {
                self.list.push(
                    STEADY,
                    inst.model,
                    s.lod_from,
                    instance_raw(input, i, s.k, 1.0, s.lod_from),
                );
            }
        }
        self.list.build();
        gpu.upload(&self.buffer, &self.list);
        if let Some(size) = self.temporal {
            let frame = self.pattern_frame.unwrap_or(input.frame);
            let [x, y] = temporal_offset(size, frame);
            let words = [size, 0, x.to_bits(), y.to_bits()];
            gpu.queue
                .write_buffer(&self.params, 0, bytemuck::cast_slice(&words));
        }
        let mut pass = gpu.begin_clear_pass(encoder, target, input.view, "dither pass");
        pass.set_bind_group(1, &self.noise_group, &[]);
        gpu.draw(
            &mut pass,
            &self.buffer,
            0,
            &self.list,
            &[&self.steady, &self.dithered],
        )
    }

    fn counterfactual(&mut self) -> Option<&mut dyn Counterfactual> {
        Some(self)
    }
}

impl Counterfactual for Dither {
    fn image_confined_to_instances(&self) -> bool {
        true
    }

    fn transition_pattern_moves(&self) -> bool {
        self.temporal.is_some()
    }

    /// The previous frame's states, and under `--noise-temporal` the previous frame's pattern phase: the
    /// pattern moves only because instances are in transition, so its motion is part of the transition.
    fn encode_before(
        &mut self,
        gpu: &SceneGpu,
        input: &FrameInput<'_>,
        history: &[&[InstanceState]],
        encoder: &mut wgpu::CommandEncoder,
        before: &RenderTarget,
    ) {
        let previous = FrameInput {
            states: history[0],
            timed: false,
            ..*input
        };
        self.pattern_frame = Some(input.frame.wrapping_sub(1));
        self.encode(gpu, &previous, encoder, before);
        self.pattern_frame = None;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The bounds are the pattern's extreme thresholds, so a k at or below the smallest gives the incoming LOD
    /// no pixel (k > t fails for every t) and a k above the largest gives the outgoing none.
    #[test]
    fn bounds_are_the_patterns_extremes() {
        let (lo, hi) = threshold_bounds(Some(&[0.5, 0.03125, 0.96875, 0.2]));
        assert_eq!((lo, hi), (0.03125, 0.96875));
        let (lo, hi) = threshold_bounds(None);
        assert_eq!(lo, 0.0);
        assert!(hi < 1.0 && hi + f32::EPSILON / 2.0 == 1.0);
        for p in [
            NoisePattern::White16,
            NoisePattern::Bayer4,
            NoisePattern::Blue64,
        ] {
            let (_, v) = threshold_texture(p, 3).unwrap();
            let (lo, hi) = threshold_bounds(Some(&v));
            assert!(v.iter().all(|&t| lo <= t && t <= hi));
            assert!(v.contains(&lo) && v.contains(&hi));
        }
    }
}
