//! `lodbench tune`: LOD switch distances chosen from a popping budget, by measurement. For each model and each
//! pair of its LODs (k, k + 1), the model alone is drawn at LOD k and at LOD k + 1, with its materials and the
//! scene's light, from N view directions at a range of distances; the image change that switching there would
//! cause is lodpop's (the RMS over the frame of the two frames' difference, with its coverage and shading parts),
//! or ColorVideoVDP's JOD between the two frames. The pair's switch distance is the nearest one from which every
//! view stays within the budget (docs/methods.md, "Choosing thresholds: lodbench tune").
//!
//! The search ([`nearest_within`]) takes each view's curve on a grid of distances, nearest first, finds the
//! farthest grid distance that breaks the budget and refines the crossing just beyond it by bisection: a curve
//! that is not monotone (a coarse LOD whose error shows only from some angles and distances) is within the budget
//! from the switch outwards, at every grid distance. A dip below the budget nearer than its last excess is not
//! taken. A LOD that breaks the budget even at the farthest distance measured (its projected size two pixels) is
//! never switched to. Every view is then measured at the switch (moving it out a grid distance while one
//! breaks the budget), and, since rasterisation makes the curve jagged between grid distances, at
//! [`DENSE_PER_STEP`] distances per grid step from the switch to where the grid's worst view stays below
//! [`NEAR_BUDGET`] of the budget, the switch moving past any distance that breaks it.

use crate::error::Result;
use crate::gpu::scene_gpu::ShadowMap;
use crate::gpu::{
    DrawList, GpuContext, InstanceRaw, RenderTarget, SceneGpu, TextureReadback, View,
};
use crate::measure::engine_rules::{Rule, RULES};
use crate::measure::metrics::rms_difference_parts;
use crate::scene::{Camera, Scene};
use glam::{Mat4, Quat, Vec3};
use serde::Serialize;

/// What a switch must keep the image change within.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
#[serde(tag = "metric", content = "value", rename_all = "snake_case")]
pub enum Budget {
    /// lodpop (RMS over the frame, sRGB-encoded, in [0, 1]) at most this.
    Lodpop(f64),
    /// ColorVideoVDP's JOD between the two frames at least this (10: no visible difference).
    Jod(f64),
}

impl Budget {
    /// How far `value` is from no change at all: lodpop itself, or 10 - JOD.
    pub fn excess(self, value: f64) -> f64 {
        match self {
            Budget::Lodpop(_) => value,
            Budget::Jod(_) => 10.0 - value,
        }
    }

    /// The budget as an excess ([`Budget::excess`]).
    pub fn excess_limit(self) -> f64 {
        match self {
            Budget::Lodpop(x) => x,
            Budget::Jod(j) => 10.0 - j,
        }
    }

    /// The worse of two values.
    pub fn worse(self, a: f64, b: f64) -> f64 {
        match self {
            Budget::Lodpop(_) => a.max(b),
            Budget::Jod(_) => a.min(b),
        }
    }

    /// Whether `value` (of this budget's metric) breaks the budget.
    pub fn broken_by(self, value: f64) -> bool {
        match self {
            Budget::Lodpop(x) => value > x,
            Budget::Jod(j) => value < j,
        }
    }
}

/// How many steps [`nearest_within`] refines a crossing by (each halves the interval of a grid step in log
/// distance).
pub const BISECTIONS: u32 = 5;

/// Where a view's curve crosses the budget.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Crossing {
    /// Within the budget at every distance measured: the switch can be as near as the nearest one.
    Everywhere,
    /// Within it from this distance outwards.
    From(f32),
    /// Broken even at the farthest distance measured.
    Never,
}

/// The nearest distance from which the curve stays within `budget`: `grid` (distances, increasing) with the value
/// at each, and `probe` measuring the value at any distance (for the bisection between the farthest excess and
/// the grid distance after it, geometric midpoints).
pub fn nearest_within(
    grid: &[(f32, f64)],
    budget: Budget,
    mut probe: impl FnMut(f32) -> Result<f64>,
) -> Result<Crossing> {
    let Some(last) = grid.iter().rposition(|&(_, v)| budget.broken_by(v)) else {
        return Ok(Crossing::Everywhere);
    };
    if last + 1 == grid.len() {
        return Ok(Crossing::Never);
    }
    let (mut lo, mut hi) = (grid[last].0, grid[last + 1].0);
    for _ in 0..BISECTIONS {
        let mid = (lo * hi).sqrt();
        if budget.broken_by(probe(mid)?) {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    Ok(Crossing::From(hi))
}

/// Where the grid's worst view (as an excess, [`Budget::excess`]) comes within this share of the budget, the
/// switch is checked between grid distances too.
pub const NEAR_BUDGET: f64 = 0.8;

/// Distances per grid step of that check.
pub const DENSE_PER_STEP: u32 = 8;

/// Whether a grid's worst excess `e` lies within [`NEAR_BUDGET`] of `budget`.
fn close_excess(e: f64, budget: Budget) -> bool {
    e > NEAR_BUDGET * budget.excess_limit()
}

/// `per_step` distances in each step of `grid` (increasing distances) that overlaps `from .. to`, evenly spaced in
/// log distance within the step, its far end included: the dense check's distances, increasing, from `from` to
/// `to`.
pub fn dense_points(grid: &[f32], from: f32, to: f32, per_step: u32) -> Vec<f32> {
    let mut out = Vec::new();
    for w in grid.windows(2) {
        let (a, b) = (w[0], w[1]);
        if b <= from || a >= to {
            continue;
        }
        for i in 1..=per_step {
            let p = a * (b / a).powf(i as f32 / per_step as f32);
            if p > from && p <= to * 1.0001 {
                out.push(p);
            }
        }
    }
    out
}

/// `n` distances from `near` to `far`, evenly spaced in log distance.
pub fn log_grid(near: f32, far: f32, n: u32) -> Vec<f32> {
    let n = n.max(2);
    let (a, b) = (near.ln(), far.ln());
    (0..n)
        .map(|i| (a + (b - a) * i as f32 / (n - 1) as f32).exp())
        .collect()
}

/// `n` view directions (unit vectors towards the camera, from the model's centre): the scene's own (+z, where the
/// default flight looks from) first, then points of a Fibonacci sphere turned by a rotation drawn from `seed`.
pub fn view_directions(n: u32, seed: u64) -> Vec<Vec3> {
    let mut rng = crate::rng::SplitMix64::new(seed);
    let turn = Quat::from_euler(
        glam::EulerRot::YXZ,
        rng.next_f32() * std::f32::consts::TAU,
        (rng.next_f32() * 2.0 - 1.0).asin(),
        rng.next_f32() * std::f32::consts::TAU,
    );
    let others = n.saturating_sub(1);
    let golden = std::f32::consts::PI * (3.0 - 5.0f32.sqrt());
    std::iter::once(Vec3::Z)
        .chain((0..others).map(|i| {
            let y = 1.0 - 2.0 * (i as f32 + 0.5) / others as f32;
            let r = (1.0 - y * y).max(0.0).sqrt();
            let phi = golden * i as f32;
            turn * Vec3::new(r * phi.cos(), y, r * phi.sin())
        }))
        .take(n as usize)
        .collect()
}

/// One measurement: model `model`'s LOD `lod` against LOD `lod + 1`, seen from view `view` at `distance` (from the
/// model's bounding-sphere centre).
#[derive(Debug, Clone, Serialize)]
pub struct Sample {
    pub model: String,
    pub lod_from: u32,
    pub lod_to: u32,
    pub view: u32,
    pub distance: f32,
    /// The bounding sphere's projected diameter over the viewport's height at `distance`.
    pub screen_size: f32,
    pub lodpop: f64,
    pub lodpop_coverage: f64,
    pub lodpop_shading: f64,
    /// With `--budget-jod`: ColorVideoVDP's JOD between the two frames.
    pub jod: Option<f64>,
    /// Whether the sample is a bisection step (not a grid distance).
    pub refined: bool,
}

/// lodpop between two frames and its coverage and shading parts, and the two frames (RGBA8).
pub type Switched = ((f64, f64, f64), [Vec<u8>; 2]);

/// Scores two frames (RGBA8): ColorVideoVDP's JOD under a JOD budget.
pub type FrameScore<'f> = &'f mut dyn FnMut(&[u8], &[u8]) -> Result<f64>;

/// Draws a scene's models one at a time, alone, at the origin, from any direction and distance.
pub struct ModelCamera<'a> {
    ctx: &'a GpuContext,
    pub scene: &'a Scene,
    gpu: SceneGpu,
    target: RenderTarget,
    readback: TextureReadback,
    list: DrawList,
    buffer: crate::gpu::InstanceBuffer,
    background: [u8; 3],
}

impl<'a> ModelCamera<'a> {
    pub fn new(ctx: &'a GpuContext, scene: &'a Scene) -> Result<ModelCamera<'a>> {
        ctx.check_viewport(scene.width, scene.height)?;
        let gpu = SceneGpu::new(ctx, scene)?;
        let (w, h) = (scene.width, scene.height);
        Ok(ModelCamera {
            ctx,
            scene,
            target: RenderTarget::new(&ctx.device, "tune target", w, h),
            readback: TextureReadback::color(&ctx.device, "tune read-back", w, h),
            list: DrawList::default(),
            buffer: gpu.create_instance_buffer("tune instance", 1),
            background: gpu.background_bytes(ctx)?,
            gpu,
        })
    }

    /// The device's bytes of the clear colour.
    pub fn background(&self) -> [u8; 3] {
        self.background
    }

    /// Model `model` at LOD `lod`, its bounding-sphere centre at the origin turned by `rotation` (its first
    /// instance's), seen from `direction` at `distance`: the frame's RGBA bytes.
    pub fn draw(
        &mut self,
        model: u32,
        lod: u32,
        rotation: Quat,
        direction: Vec3,
        distance: f32,
    ) -> Result<Vec<u8>> {
        let m = &self.scene.models[model as usize];
        let eye = direction * distance;
        let up = if direction.y.abs() > 0.99 {
            Vec3::Z
        } else {
            Vec3::Y
        };
        let aspect = self.scene.width as f32 / self.scene.height as f32;
        let near = (distance - 1.5 * m.radius).max(distance * 1e-3);
        let camera = Camera {
            eye,
            view: Mat4::look_at_rh(eye, Vec3::ZERO, up),
            proj: Mat4::perspective_rh(self.scene.fov_y, aspect, near, distance + 1.5 * m.radius),
        };
        self.gpu.write_camera(&camera);
        let matrix = Mat4::from_quat(rotation)
            * Mat4::from_scale(Vec3::splat(m.scale))
            * Mat4::from_translation(-m.center);
        let [r, g, b] = m.color_of(lod);
        self.list.clear();
        self.list.push(
            0,
            model,
            lod,
            InstanceRaw::new(&matrix, [r, g, b, 0.0], [0.0, 1.0, lod as f32, 0.0]),
        );
        self.list.build();
        self.gpu.upload(&self.buffer, &self.list);
        let mut encoder = self.gpu.device.create_command_encoder(&Default::default());
        {
            let mut pass = self.gpu.begin_clear_pass(
                &mut encoder,
                &self.target,
                View::lit_by(ShadowMap::NONE),
                "tune pass",
            );
            self.gpu.draw(
                &mut pass,
                &self.buffer,
                0,
                &self.list,
                &[&self.gpu.opaque_pipeline],
            );
        }
        self.readback.encode_copy(&mut encoder, &self.target);
        self.gpu.queue.submit([encoder.finish()]);
        let px = self.readback.read(self.ctx)?;
        self.ctx.check_errors()?;
        Ok(px)
    }

    /// lodpop between LOD `lod` and LOD `lod + 1` of `model` from `direction` at `distance`: (lodpop, coverage,
    /// shading), and the two frames.
    pub fn switch_at(
        &mut self,
        model: u32,
        lod: u32,
        rotation: Quat,
        direction: Vec3,
        distance: f32,
    ) -> Result<Switched> {
        let a = self.draw(model, lod, rotation, direction, distance)?;
        let b = self.draw(model, lod + 1, rotation, direction, distance)?;
        Ok((rms_difference_parts(&a, &b, self.background), [a, b]))
    }
}

/// What `lodbench tune` measures with.
#[derive(Debug, Clone, Serialize)]
pub struct TuneSettings {
    pub budget: Budget,
    pub views: u32,
    /// Grid distances per view.
    pub distances: u32,
    /// The view directions' seed.
    pub seed: u64,
    /// `--speed` (world units per second) and `--fps`: the camera's speed the blending methods' bands are for.
    pub speed: Option<(f32, f32)>,
    /// The schedule's `--band` (its half-width as a fraction of a switch distance): consecutive switches are kept
    /// far enough apart that their bands do not overlap, as `lodbench run` requires.
    pub band: f32,
}

/// A blending method's transition at a pair: the nearest switch whose band (a relative half-width, the
/// schedule's `--band`) keeps every frame's change within the budget at the camera's speed.
#[derive(Debug, Clone, Serialize)]
pub struct BlendBand {
    pub method: &'static str,
    pub switch_distance: f32,
    /// Half-width of the band as a fraction of the switch distance (`--band`).
    pub band: f32,
    /// Frames the transition lasts at the camera's speed.
    pub frames: u32,
}

/// One pair's switch.
#[derive(Debug, Clone, Serialize)]
pub struct PairSwitch {
    pub lod_from: u32,
    pub lod_to: u32,
    pub triangles_from: usize,
    pub triangles_to: usize,
    /// Where the hard switch may happen: the nearest distance from which every view stays within the budget
    /// (None: no distance measured does; the coarser LOD is not used).
    pub switch_distance: Option<f32>,
    /// The bounding sphere's projected diameter over the viewport's height there.
    pub screen_size: Option<f32>,
    /// The view whose curve set the distance.
    pub limiting_view: Option<u32>,
    /// The largest value over the views at the switch (the budget's metric).
    pub value_at_switch: Option<f64>,
    /// How far beyond the switch the dense check went (where the grid's worst view stays below
    /// [`NEAR_BUDGET`] of the budget from there on), and the worst it saw from the switch to there.
    pub checked_to: Option<f32>,
    pub checked_worst: Option<f64>,
    /// LOD `lod_to`'s simplifier error (object-space units) and what it projects to at the switch, in pixels:
    /// the error bound an engine's rule (Godot's pixel threshold, Simplygon's deviation) would have used there.
    pub error_abs: f32,
    pub error_px_at_switch: Option<f32>,
    /// Each view's own crossing (None: never within).
    pub per_view: Vec<Option<f32>>,
    /// With `--speed`: alpha's, dither's and geomorph's bands.
    pub bands: Vec<BlendBand>,
    /// Where the engines' rules would switch, and what the views see there.
    pub rules: Vec<RuleAt>,
}

/// An engine's rule at one pair: where it switches and the budget's figure there (the worst over the views).
#[derive(Debug, Clone, Serialize)]
pub struct RuleAt {
    pub rule: Rule,
    pub distance: f32,
    pub screen_size: f32,
    pub value: Option<f64>,
    /// Whether every view stays within the budget at the rule's distance.
    pub within: bool,
}

/// One model's switches.
#[derive(Debug, Clone, Serialize)]
pub struct ModelSwitches {
    pub model: u32,
    pub name: String,
    /// Bounding-sphere radius (world units) and centre (model space).
    pub radius: f32,
    pub center: [f32; 3],
    /// The grid of distances measured: where the model fits the view, to where it is two pixels across.
    pub near: f32,
    pub far: f32,
    pub pairs: Vec<PairSwitch>,
}

/// The blending methods tune gives bands for, and whether a frame's change falls with the square root of the
/// transition's frames (dither: a share of the pixels flips fully each frame) or with the frames (a linear blend).
pub const BLEND_METHODS: [(&str, bool); 3] =
    [("alpha", false), ("dither", true), ("geomorph", false)];

/// The frames a blending method needs for each frame's change to stay within `budget` when the whole change is
/// `pop`: a linear blend (alpha, geomorph) changes the frame by pop / n a frame over n frames; dither flips a share
/// 1 / n of the pixels fully each frame, an RMS of pop / sqrt(n).
pub fn frames_needed(pop: f64, budget: f64, sqrt_law: bool) -> u32 {
    if pop <= budget {
        return 1;
    }
    let r = pop / budget;
    (if sqrt_law { r * r } else { r }).ceil().min(1e6) as u32
}

/// The nearest grid distance at which a blending method's band fits: `worst` is the largest value over the views
/// at each grid distance (increasing distances), `step` the camera's travel per frame, `after` the distance the
/// previous pair's band ends at; the band around a candidate d reaches d (1 +- h), h = n step / (2 d), n the frames
/// the largest change within the band needs; it must stay below half the distance and clear the previous band.
pub fn blend_band(
    worst: &[(f32, f64)],
    budget: f64,
    step: f32,
    after: f32,
    sqrt_law: bool,
) -> Option<(f32, f32, u32)> {
    for &(d, _) in worst {
        let mut h = 0.0f32;
        let mut n = 1;
        for _ in 0..8 {
            let pop = worst
                .iter()
                .filter(|(x, _)| *x >= d * (1.0 - h) && *x <= d * (1.0 + h))
                .map(|p| p.1)
                .fold(0.0f64, f64::max);
            n = frames_needed(pop, budget, sqrt_law);
            let next = n as f32 * step / (2.0 * d);
            if (next - h).abs() <= 1e-6 {
                break;
            }
            h = next;
        }
        if h < 0.45 && d * (1.0 - h) >= after {
            return Some((d, h, n));
        }
    }
    None
}

/// The budget's figure at distance `d` for the pair (`lod`, `lod + 1`), the worst over `views` (the largest
/// lodpop, the smallest JOD); None without views.
#[allow(
    clippy::too_many_arguments,
    reason = "the pair, its pose and the measurement's settings"
)]
fn worst_at(
    camera: &mut ModelCamera<'_>,
    model: u32,
    lod: u32,
    rotation: Quat,
    views: &[Vec3],
    d: f32,
    settings: &TuneSettings,
    jod: FrameScore<'_>,
) -> Result<Option<f64>> {
    let mut worst = None::<f64>;
    for &dir in views {
        let ((pop, _, _), [a, b]) = camera.switch_at(model, lod, rotation, dir, d)?;
        let v = match settings.budget {
            Budget::Jod(_) => jod(&a, &b)?,
            Budget::Lodpop(_) => pop,
        };
        worst = Some(match (worst, settings.budget) {
            (None, _) => v,
            (Some(x), Budget::Lodpop(_)) => x.max(v),
            (Some(x), Budget::Jod(_)) => x.min(v),
        });
    }
    Ok(worst)
}

/// The switches of every pair of `model` (drawn by `camera`), each view's grid measured and refined, every sample
/// appended to `samples`. `jod` scores two frames (RGBA bytes) when the budget is a JOD.
pub fn tune_model(
    camera: &mut ModelCamera<'_>,
    model: u32,
    rotation: Quat,
    settings: &TuneSettings,
    views: &[Vec3],
    jod: FrameScore<'_>,
    samples: &mut Vec<Sample>,
) -> Result<ModelSwitches> {
    let scene = camera.scene;
    let m = &scene.models[model as usize];
    let range = DistanceRange::of(scene, m.radius, settings.distances);
    let mut pairs: Vec<PairSwitch> = Vec::new();
    let errors: Vec<f32> = m.chain.lods[1..]
        .iter()
        .map(|l| l.error_abs * m.scale)
        .collect();
    let rule_distances: Vec<Vec<f32>> = RULES
        .iter()
        .map(|r| r.distances(&errors, m.radius, scene.height, scene.fov_y))
        .collect();
    let mut tuning = ModelTuning {
        camera,
        model,
        rotation,
        settings,
        views,
        jod,
        samples,
    };
    // Per blending method, where its previous band ends.
    let mut band_end = [0.0f32; 3];
    for lod in 0..m.chain.lods.len().saturating_sub(1) as u32 {
        let pair = tuning.tune_pair(lod, &range, &rule_distances, pairs.last(), &mut band_end)?;
        pairs.push(pair);
    }
    Ok(ModelSwitches {
        model,
        name: m.name.clone(),
        radius: m.radius,
        center: m.center.to_array(),
        near: range.near,
        far: range.far,
        pairs,
    })
}

/// The distances a model's pairs are measured over: from where it fills the viewport to where its bounding
/// sphere's radius projects to one pixel (at least 1% farther), on a log grid.
struct DistanceRange {
    near: f32,
    far: f32,
    grid: Vec<f32>,
    /// tan(fov_y / 2).
    tan: f32,
    radius: f32,
}

impl DistanceRange {
    /// The range of a model of bounding radius `radius` in `scene`, with `distances` grid distances.
    fn of(scene: &Scene, radius: f32, distances: u32) -> DistanceRange {
        let (w, h) = (scene.width, scene.height);
        let tan = (scene.fov_y * 0.5).tan();
        let near = crate::scene::bunny::fit_distance(radius, w, h, scene.fov_y);
        let far = (radius * h as f32 / (2.0 * tan)).max(near * 1.01);
        DistanceRange {
            near,
            far,
            grid: log_grid(near, far, distances),
            tan,
            radius,
        }
    }

    /// The bounding sphere's projected size at distance `d` ([`PairSwitch::screen_size`]).
    fn screen(&self, d: f32) -> f32 {
        self.radius / (d * self.tan)
    }
}

/// The views' curves at one pair.
struct Curves {
    /// Each view's crossing ([`PairSwitch::per_view`]).
    per_view: Vec<Option<f32>>,
    /// The worst excess over the views at each grid distance.
    worst: Vec<(f32, f64)>,
}

/// A pair's switch and how far beyond it the dense check went ([`PairSwitch`]'s fields of the same names).
struct Checked {
    switch: Option<f32>,
    value_at_switch: Option<f64>,
    checked_to: Option<f32>,
    checked_worst: Option<f64>,
}

/// One model's tuning: what every pair of it is drawn, scored and recorded with.
struct ModelTuning<'t, 'c> {
    camera: &'t mut ModelCamera<'c>,
    model: u32,
    rotation: Quat,
    settings: &'t TuneSettings,
    views: &'t [Vec3],
    jod: FrameScore<'t>,
    samples: &'t mut Vec<Sample>,
}

impl ModelTuning<'_, '_> {
    /// [`worst_at`] for the pair (`lod`, `lod + 1`) at distance `d`.
    fn worst(&mut self, lod: u32, d: f32) -> Result<Option<f64>> {
        worst_at(
            self.camera,
            self.model,
            lod,
            self.rotation,
            self.views,
            d,
            self.settings,
            self.jod,
        )
    }

    /// The pair (`lod`, `lod + 1`): each view's crossing, the switch (beyond the band of the `previous` pair's,
    /// moved out past every distance that breaks the budget), the engines' rules and, with `--speed`, the
    /// blending methods' bands (each after its `band_end`, moved on).
    fn tune_pair(
        &mut self,
        lod: u32,
        range: &DistanceRange,
        rule_distances: &[Vec<f32>],
        previous: Option<&PairSwitch>,
        band_end: &mut [f32; 3],
    ) -> Result<PairSwitch> {
        let scene = self.camera.scene;
        let m = &scene.models[self.model as usize];
        let Curves { per_view, worst } = self.measure_views(lod, range)?;
        let limiting = limiting_view(&per_view, range.near);
        let switch = first_switch(limiting, previous, self.settings.band);
        let (switch, value_at_switch) = self.past_grid_breaks(lod, &range.grid, switch)?;
        let checked = self.dense_check(lod, &range.grid, &worst, switch, value_at_switch)?;
        let rules = self.rules_at(lod, range, rule_distances)?;
        let error_abs = m.chain.lods[lod as usize + 1].error_abs;
        let bands = blend_bands(self.settings, &worst, checked.switch, band_end);
        let switch = checked.switch;
        Ok(PairSwitch {
            lod_from: lod,
            lod_to: lod + 1,
            triangles_from: m.chain.lods[lod as usize].mesh.triangle_count(),
            triangles_to: m.chain.lods[lod as usize + 1].mesh.triangle_count(),
            switch_distance: switch,
            screen_size: switch.map(|d| range.screen(d)),
            limiting_view: limiting.map(|l| l.0),
            value_at_switch: checked.value_at_switch,
            checked_to: checked.checked_to,
            checked_worst: checked.checked_worst,
            error_abs,
            error_px_at_switch: switch.map(|d| {
                crate::geometry::lod::switch_distance(
                    error_abs,
                    m.scale,
                    1.0,
                    scene.height,
                    scene.fov_y,
                ) / d
            }),
            per_view,
            bands,
            rules,
        })
    }

    /// Every view's curve over the grid for the pair (`lod`, `lod + 1`), each sample recorded: each view's
    /// crossing (refined between grid distances), and the worst excess over the views at each grid distance.
    fn measure_views(&mut self, lod: u32, range: &DistanceRange) -> Result<Curves> {
        let scene = self.camera.scene;
        let m = &scene.models[self.model as usize];
        let (grid, near) = (&range.grid, range.near);
        let ModelTuning {
            camera,
            model,
            rotation,
            settings,
            views,
            jod,
            samples,
        } = self;
        let mut per_view = Vec::with_capacity(views.len());
        let mut worst: Vec<(f32, f64)> = grid.iter().map(|&d| (d, 0.0)).collect();
        for (v, &dir) in views.iter().enumerate() {
            let mut measure = |d: f32, refined: bool| -> Result<f64> {
                let ((pop, cov, shade), [a, b]) =
                    camera.switch_at(*model, lod, *rotation, dir, d)?;
                let j = match settings.budget {
                    Budget::Jod(_) => Some(jod(&a, &b)?),
                    Budget::Lodpop(_) => None,
                };
                samples.push(Sample {
                    model: m.name.clone(),
                    lod_from: lod,
                    lod_to: lod + 1,
                    view: v as u32,
                    distance: d,
                    screen_size: range.screen(d),
                    lodpop: pop,
                    lodpop_coverage: cov,
                    lodpop_shading: shade,
                    jod: j,
                    refined,
                });
                Ok(j.unwrap_or(pop))
            };
            let mut curve = Vec::with_capacity(grid.len());
            for &d in grid {
                curve.push((d, measure(d, false)?));
            }
            for (w, c) in worst.iter_mut().zip(&curve) {
                w.1 = match settings.budget {
                    Budget::Lodpop(_) => w.1.max(c.1),
                    Budget::Jod(_) => w.1.max(10.0 - c.1),
                };
            }
            per_view.push(
                match nearest_within(&curve, settings.budget, |d| measure(d, true))? {
                    Crossing::Everywhere => Some(near),
                    Crossing::From(d) => Some(d),
                    Crossing::Never => None,
                },
            );
        }
        Ok(Curves { per_view, worst })
    }

    /// Every view at the switch: the views whose crossing lies nearer are within the budget at every grid
    /// distance beyond theirs, but may break it between two; then the switch moves out to the next grid
    /// distance, where none does. The switch and the worst figure over the views there.
    fn past_grid_breaks(
        &mut self,
        lod: u32,
        grid: &[f32],
        mut switch: Option<f32>,
    ) -> Result<(Option<f32>, Option<f64>)> {
        let mut value_at_switch = None;
        while let Some(d) = switch {
            let worst_here = self.worst(lod, d)?;
            value_at_switch = worst_here;
            match worst_here {
                Some(v) if self.settings.budget.broken_by(v) => {
                    switch = grid.iter().copied().find(|&g| g > d * 1.0001);
                }
                _ => break,
            }
        }
        Ok((switch, value_at_switch))
    }

    /// Between grid distances the figure is not smooth: a pixel's coverage flips with sub-pixel motion, and
    /// lodpop moves by some per cent from one distance to a nearby one. Where the grid's worst view comes
    /// within NEAR_BUDGET of the budget beyond the switch, the switch is checked at DENSE_PER_STEP distances per
    /// grid step, every view, and moves past any that breaks the budget.
    fn dense_check(
        &mut self,
        lod: u32,
        grid: &[f32],
        worst: &[(f32, f64)],
        mut switch: Option<f32>,
        mut value_at_switch: Option<f64>,
    ) -> Result<Checked> {
        let settings = self.settings;
        let mut checked_max = value_at_switch;
        let mut checked_to = switch;
        if let Some(mut d) = switch {
            let last_close = worst
                .iter()
                .rposition(|&(_, e)| close_excess(e, settings.budget));
            let until = last_close
                .and_then(|i| grid.get(i + 1).copied())
                .unwrap_or(d)
                .max(d);
            let points = dense_points(grid, d, until, DENSE_PER_STEP);
            let mut worst_checked = value_at_switch;
            for (i, &p) in points.iter().enumerate() {
                if p < d {
                    continue;
                }
                let v = self.worst(lod, p)?;
                if p == d {
                    // The switch moved here: its own figure.
                    value_at_switch = v;
                }
                match v {
                    Some(v) if settings.budget.broken_by(v) => {
                        // Past it: the next dense distance, or the grid distance after the last (within the
                        // budget at every view: the check ends where the grid stays below NEAR_BUDGET of it).
                        let next = points
                            .get(i + 1)
                            .copied()
                            .or_else(|| grid.iter().copied().find(|&g| g > p * 1.0001));
                        let Some(next) = next else {
                            switch = None;
                            break;
                        };
                        d = next;
                        worst_checked = None;
                        if i + 1 == points.len() {
                            value_at_switch = self.worst(lod, d)?;
                            worst_checked = value_at_switch;
                        }
                    }
                    Some(v) => {
                        worst_checked = Some(match worst_checked {
                            None => v,
                            Some(x) => settings.budget.worse(x, v),
                        });
                    }
                    None => {}
                }
            }
            if switch.is_some() {
                switch = Some(d);
            } else {
                value_at_switch = None;
                worst_checked = None;
            }
            checked_max = worst_checked;
            checked_to = switch.map(|s| until.max(s));
        }
        Ok(Checked {
            switch,
            value_at_switch,
            checked_to,
            checked_worst: checked_max,
        })
    }

    /// The engines' rules at the pair (`lod`, `lod + 1`): their distance and the worst the views see there.
    fn rules_at(
        &mut self,
        lod: u32,
        range: &DistanceRange,
        rule_distances: &[Vec<f32>],
    ) -> Result<Vec<RuleAt>> {
        let mut rules = Vec::with_capacity(RULES.len());
        for (rule, distances) in RULES.iter().zip(rule_distances) {
            let d = distances[lod as usize];
            let value = self.worst(lod, d)?;
            rules.push(RuleAt {
                rule: *rule,
                distance: d,
                screen_size: range.screen(d),
                value,
                within: value.is_some_and(|v| !self.settings.budget.broken_by(v)),
            });
        }
        Ok(rules)
    }
}

/// The view whose crossing is farthest, and that distance; None when some view never comes within the budget.
fn limiting_view(per_view: &[Option<f32>], near: f32) -> Option<(u32, f32)> {
    if per_view.iter().any(Option::is_none) {
        None
    } else {
        per_view
            .iter()
            .enumerate()
            .max_by(|a, b| a.1.unwrap_or(0.0).total_cmp(&b.1.unwrap_or(0.0)))
            .map(|(v, d)| (v as u32, d.unwrap_or(near)))
    }
}

/// The switch the views ask for: the `limiting` view's, no nearer than the `previous` pair's band (half-width
/// `b`) allows; none once the previous pair has none.
fn first_switch(
    limiting: Option<(u32, f32)>,
    previous: Option<&PairSwitch>,
    b: f32,
) -> Option<f32> {
    // A coarser LOD never switches in nearer than the finer one before it, and its transition band starts
    // where the one before ends (s_k (1 - b) > s_(k-1) (1 + b)).
    let floor = previous
        .and_then(|p| p.switch_distance)
        .map_or(0.0, |d| d * (1.0 + b) / (1.0 - b) * 1.001);
    match (limiting, previous) {
        (_, Some(p)) if p.switch_distance.is_none() => None,
        (Some((_, d)), _) => Some(d.max(floor)),
        (None, _) => None,
    }
}

/// With `--speed` and a lodpop budget: alpha's, dither's and geomorph's bands at the hard `switch` or nearer
/// (`worst`: the grid's worst excess), each starting where its previous one ends (`band_end`, moved on).
fn blend_bands(
    settings: &TuneSettings,
    worst: &[(f32, f64)],
    switch: Option<f32>,
    band_end: &mut [f32; 3],
) -> Vec<BlendBand> {
    let mut bands = Vec::new();
    if let (Some((speed, fps)), Budget::Lodpop(budget), Some(hard)) =
        (settings.speed, settings.budget, switch)
    {
        let step = speed / fps.max(1e-6);
        for (k, (method, sqrt_law)) in BLEND_METHODS.into_iter().enumerate() {
            // A band around a distance no farther than the hard switch's, or the hard switch itself.
            let candidates: Vec<(f32, f64)> =
                worst.iter().copied().filter(|(d, _)| *d <= hard).collect();
            let (d, h, n) = blend_band(&candidates, budget, step, band_end[k], sqrt_law)
                .unwrap_or((hard.max(band_end[k] * 1.001), 0.0, 1));
            band_end[k] = d * (1.0 + h);
            bands.push(BlendBand {
                method,
                switch_distance: d,
                band: h,
                frames: n,
            });
        }
    }
    bands
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A curve with its budget planted at a known distance: the search finds it to the bisection's precision,
    /// whether the curve falls smoothly or has a dip below the budget nearer than its last excess.
    #[test]
    fn the_search_finds_a_planted_threshold() {
        let threshold = 7.3f32;
        // lodpop falls as 1 / d^2 and equals the budget at the threshold.
        let budget = 0.01;
        let value = |d: f32| budget * f64::from(threshold / d).powi(2);
        let grid: Vec<(f32, f64)> = log_grid(1.0, 100.0, 24)
            .into_iter()
            .map(|d| (d, value(d)))
            .collect();
        let found = nearest_within(&grid, Budget::Lodpop(budget), |d| Ok(value(d))).unwrap();
        let Crossing::From(d) = found else {
            panic!("{found:?}")
        };
        // One grid step is a factor 100^(1/23) = 1.22; five bisections leave 1.22^(1/32), 0.6 %.
        assert!(d >= threshold && d < threshold * 1.007, "{d}");
        // A dip within the budget at 3 units (nearer than the excess at 4 to 7.3) is not taken.
        let dipped = |d: f32| {
            if (2.5..3.5).contains(&d) {
                0.0
            } else {
                value(d)
            }
        };
        let grid: Vec<(f32, f64)> = log_grid(1.0, 100.0, 24)
            .into_iter()
            .map(|d| (d, dipped(d)))
            .collect();
        assert!(grid
            .iter()
            .any(|&(d, v)| (2.5..3.5).contains(&d) && v == 0.0));
        let Crossing::From(d) =
            nearest_within(&grid, Budget::Lodpop(budget), |d| Ok(dipped(d))).unwrap()
        else {
            panic!()
        };
        assert!(d >= threshold && d < threshold * 1.007, "{d}");
        // Within everywhere, and never within.
        assert_eq!(
            nearest_within(&grid, Budget::Lodpop(1.0), |_| Ok(0.0)).unwrap(),
            Crossing::Everywhere
        );
        assert_eq!(
            nearest_within(&grid, Budget::Lodpop(1e-9), |_| Ok(1.0)).unwrap(),
            Crossing::Never
        );
        // A JOD budget: higher is better.
        let jod = |d: f32| 10.0 - f64::from(threshold / d);
        let grid: Vec<(f32, f64)> = log_grid(1.0, 100.0, 24)
            .into_iter()
            .map(|d| (d, jod(d)))
            .collect();
        let Crossing::From(d) = nearest_within(&grid, Budget::Jod(9.0), |d| Ok(jod(d))).unwrap()
        else {
            panic!()
        };
        assert!(d >= threshold && d < threshold * 1.007, "{d}");
    }

    /// A blend spreads a change over frames: linear blends need pop / budget frames, dither (pop / budget)^2; the
    /// nearest band that fits clears the previous band and stays under half the distance.
    #[test]
    fn blend_bands_spread_the_change_over_enough_frames() {
        assert_eq!(frames_needed(0.004, 0.001, false), 4);
        assert_eq!(frames_needed(0.004, 0.001, true), 16);
        assert_eq!(frames_needed(0.0005, 0.001, true), 1);
        // pop = 0.01 / d at distance d; budget 0.001; the camera moves 0.1 a frame.
        let worst: Vec<(f32, f64)> = log_grid(1.0, 100.0, 40)
            .into_iter()
            .map(|d| (d, 0.01 / f64::from(d)))
            .collect();
        let (d, h, n) = blend_band(&worst, 0.001, 0.1, 0.0, false).unwrap();
        // Every grid distance inside the band needs at most n frames, and the band is n frames of travel.
        assert!(h < 0.45, "{d} {h} {n}");
        for &(x, pop) in &worst {
            if x >= d * (1.0 - h) && x <= d * (1.0 + h) {
                assert!(frames_needed(pop, 0.001, false) <= n, "{x}");
            }
        }
        assert!((h - n as f32 * 0.1 / (2.0 * d)).abs() < 1e-5);
        // The nearest such distance: the grid distance before it cannot hold its band under half its distance.
        let before = worst.iter().rev().find(|p| p.0 < d).unwrap();
        assert!(
            frames_needed(before.1, 0.001, false) as f32 * 0.1 / (2.0 * before.0) >= 0.45 * 0.5
        );
        // Beyond the previous band's end only.
        let (d2, h2, _) = blend_band(&worst, 0.001, 0.1, 20.0, false).unwrap();
        assert!(d2 * (1.0 - h2) >= 20.0 && d2 > d);
        // dither needs more frames, so a wider band, so a farther switch.
        let (dd, _, nd) = blend_band(&worst, 0.001, 0.1, 0.0, true).unwrap();
        assert!(dd >= d && nd >= n);
    }

    /// The dense check's distances: per_step of them in each grid step from the switch to where it ends,
    /// increasing, the far end of each step included and nothing before the switch.
    #[test]
    fn dense_points_fill_the_steps_from_the_switch() {
        let grid = log_grid(1.0, 16.0, 5); // 1, 2, 4, 8, 16
        let p = dense_points(&grid, 2.5, 8.0, 4);
        assert!(p.windows(2).all(|w| w[1] > w[0]));
        assert!(p.iter().all(|&x| x > 2.5 && x <= 8.0 * 1.0001));
        // The step 2..4 past 2.5 (2.83, 3.36, 4), the whole step 4..8 (4.76, 5.66, 6.73, 8).
        assert_eq!(p.len(), 7, "{p:?}");
        assert!((p[2] - 4.0).abs() < 1e-4 && (p[6] - 8.0).abs() < 1e-4);
        assert!(dense_points(&grid, 5.0, 5.0, 4).is_empty());
    }

    #[test]
    fn views_start_at_the_scenes_own_and_are_seeded() {
        let a = view_directions(8, 3);
        assert_eq!(a.len(), 8);
        assert_eq!(a[0], Vec3::Z);
        assert!(a.iter().all(|v| (v.length() - 1.0).abs() < 1e-5));
        assert_eq!(a, view_directions(8, 3));
        assert_ne!(a, view_directions(8, 4));
        let g = log_grid(2.0, 32.0, 5);
        assert!(
            (g[0] - 2.0).abs() < 1e-5 && (g[4] - 32.0).abs() < 1e-4 && (g[2] - 8.0).abs() < 1e-4
        );
    }
}
