//! The per-model driver: a model's distance range, each pair's curves over the views, the switch found and
//! checked densely, the engines' rules measured there.

use crate::error::Result;
use crate::geometry::projection::{fit_distance, screen_size, switch_distance};
use crate::measure::engine_rules::RULES;
use crate::scene::Scene;
use glam::{Quat, Vec3};
use std::collections::HashMap;

use crate::measure::switch_tuning::bands::blend_bands;
use crate::measure::switch_tuning::camera::{FrameScore, ModelCamera};
use crate::measure::switch_tuning::frame_cache::{FrameCache, FRAME_CACHE_BYTES};
use crate::measure::switch_tuning::outcome::Budget;
use crate::measure::switch_tuning::outcome::{
    ModelSwitches, PairSwitch, RuleAt, Sample, TuneSettings,
};
#[cfg(doc)]
use crate::measure::switch_tuning::search::NEAR_BUDGET;
use crate::measure::switch_tuning::search::{
    close_excess, dense_points, first_switch, limiting_view, log_grid, nearest_within, Crossing,
    DENSE_PER_STEP,
};

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
        measured: HashMap::new(),
        kept: FrameCache::new(FRAME_CACHE_BYTES),
    };
    if settings.full_grid() {
        tuning.measure_grid(&range.grid)?;
    }
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
pub(super) struct DistanceRange {
    pub(super) near: f32,
    pub(super) far: f32,
    pub(super) grid: Vec<f32>,
    pub(super) fov_y: f32,
    pub(super) radius: f32,
}

impl DistanceRange {
    /// The range of a model of bounding radius `radius` in `scene`, with `distances` grid distances.
    pub(super) fn of(scene: &Scene, radius: f32, distances: u32) -> DistanceRange {
        let (w, h) = (scene.width, scene.height);
        let near = fit_distance(radius, w, h, scene.fov_y);
        // Where the radius projects to one pixel.
        let far = switch_distance(radius, 1.0, 1.0, h, scene.fov_y).max(near * 1.01);
        DistanceRange {
            near,
            far,
            grid: log_grid(near, far, distances),
            fov_y: scene.fov_y,
            radius,
        }
    }

    /// The bounding sphere's projected size at distance `d` ([`PairSwitch::screen_size`]).
    pub(super) fn screen(&self, d: f32) -> f32 {
        screen_size(self.radius, d, self.fov_y)
    }
}

/// The views' curves at one pair.
pub(super) struct Curves {
    /// Each view's crossing ([`PairSwitch::per_view`]).
    pub(super) per_view: Vec<Option<f32>>,
    /// The worst excess over the views at each grid distance.
    pub(super) worst: Vec<(f32, f64)>,
}

/// A pair's switch and how far beyond it the dense check went ([`PairSwitch`]'s fields of the same names).
pub(super) struct Checked {
    pub(super) switch: Option<f32>,
    pub(super) value_at_switch: Option<f64>,
    pub(super) checked_to: Option<f32>,
    pub(super) checked_worst: Option<f64>,
}

/// One model's tuning: what every pair of it is drawn, scored and recorded with.
pub(super) struct ModelTuning<'t, 'c> {
    pub(super) camera: &'t mut ModelCamera<'c>,
    pub(super) model: u32,
    pub(super) rotation: Quat,
    pub(super) settings: &'t TuneSettings,
    pub(super) views: &'t [Vec3],
    pub(super) jod: FrameScore<'t>,
    pub(super) samples: &'t mut Vec<Sample>,
    /// Every pair's figures measured so far, by (the pair's first LOD, view, distance's bits): each is drawn and
    /// scored once.
    pub(super) measured: HashMap<(u32, u32, u32), Measured>,
    /// The frames of each pair's coarser LOD drawn away from the grid, for the next pair.
    pub(super) kept: FrameCache,
}

/// One pair's figures at one view and distance: lodpop and its coverage and shading parts, and ColorVideoVDP's
/// JOD under a JOD budget.
#[derive(Debug, Clone, Copy)]
pub(super) struct Measured {
    pub(super) lodpop: f64,
    pub(super) coverage: f64,
    pub(super) shading: f64,
    pub(super) jod: Option<f64>,
}

impl Measured {
    /// The budget's figure: JOD under a JOD budget, else lodpop.
    pub(super) fn value(&self) -> f64 {
        self.jod.unwrap_or(self.lodpop)
    }
}

impl ModelTuning<'_, '_> {
    /// The budget's figure at distance `d` for the pair (`lod`, `lod + 1`), the worst over the views (the
    /// largest lodpop, the smallest JOD); None without views.
    pub(super) fn worst(&mut self, lod: u32, d: f32) -> Result<Option<f64>> {
        let mut worst = None::<f64>;
        for v in 0..self.views.len() {
            let x = self.measure(lod, v, d)?.value();
            worst = Some(worst.map_or(x, |w| self.settings.budget.worse(w, x)));
        }
        Ok(worst)
    }

    /// The pair (`lod`, `lod + 1`)'s figures at view `v` and distance `d`, drawn and scored unless they were
    /// already.
    pub(super) fn measure(&mut self, lod: u32, v: usize, d: f32) -> Result<Measured> {
        let key = (lod, v as u32, d.to_bits());
        if let Some(m) = self.measured.get(&key) {
            return Ok(*m);
        }
        let a = match self.kept.take((lod, v as u32, d.to_bits())) {
            Some(a) => a,
            None => self.frame(lod, v, d)?,
        };
        let b = self.frame(lod + 1, v, d)?;
        let m = self.figures(&a, &b)?;
        self.measured.insert(key, m);
        let lods = self.camera.scene.models[self.model as usize]
            .chain
            .lods
            .len();
        if lod as usize + 2 < lods {
            // The next pair's finer LOD.
            self.kept.put((lod + 1, v as u32, d.to_bits()), b);
        }
        Ok(m)
    }

    /// Every pair's figures at every view and grid distance, each LOD drawn once at each (a LOD ends one pair
    /// and starts the next).
    pub(super) fn measure_grid(&mut self, grid: &[f32]) -> Result<()> {
        let lods = self.camera.scene.models[self.model as usize]
            .chain
            .lods
            .len() as u32;
        for v in 0..self.views.len() {
            for &d in grid {
                let mut previous = self.frame(0, v, d)?;
                for lod in 1..lods {
                    let frame = self.frame(lod, v, d)?;
                    let m = self.figures(&previous, &frame)?;
                    self.measured.insert((lod - 1, v as u32, d.to_bits()), m);
                    previous = frame;
                }
            }
        }
        Ok(())
    }

    /// LOD `lod` from view `v` at distance `d`: the whole frame under a JOD budget (ColorVideoVDP scores whole
    /// frames), else the crop outside which it is the clear colour ([`ModelCamera::crop`]).
    fn frame(&mut self, lod: u32, v: usize, d: f32) -> Result<Vec<u8>> {
        let (model, rotation, dir) = (self.model, self.rotation, self.views[v]);
        match self.settings.budget {
            Budget::Jod(_) => self.camera.draw(model, lod, rotation, dir, d),
            Budget::Lodpop(_) => {
                let rect = self.camera.crop(model, d);
                self.camera.draw_rect(model, lod, rotation, dir, d, rect)
            }
        }
    }

    /// The figures of a switch between two of [`ModelTuning::frame`]'s frames (the same view and distance).
    fn figures(&mut self, a: &[u8], b: &[u8]) -> Result<Measured> {
        let (lodpop, coverage, shading) = self.camera.pop_of(a, b);
        let jod = match self.settings.budget {
            Budget::Jod(_) => Some((self.jod)(a, b)?),
            Budget::Lodpop(_) => None,
        };
        Ok(Measured {
            lodpop,
            coverage,
            shading,
            jod,
        })
    }

    /// The pair (`lod`, `lod + 1`): each view's crossing, the switch (beyond the band of the `previous` pair's,
    /// moved out past every distance that breaks the budget), the engines' rules and, with `--speed`, the
    /// blending methods' bands (each after its `band_end`, moved on).
    pub(super) fn tune_pair(
        &mut self,
        lod: u32,
        range: &DistanceRange,
        rule_distances: &[Vec<f32>],
        previous: Option<&PairSwitch>,
        band_end: &mut [f32; 3],
    ) -> Result<PairSwitch> {
        let scene = self.camera.scene;
        let m = &scene.models[self.model as usize];
        self.kept.drop_below(lod);
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
            error_px_at_switch: switch
                .map(|d| switch_distance(error_abs, m.scale, 1.0, scene.height, scene.fov_y) / d),
            per_view,
            bands,
            rules,
        })
    }

    /// Every view's curve over the grid for the pair (`lod`, `lod + 1`), each sample recorded: each view's
    /// crossing (refined between grid distances), and the worst excess over the views at each grid distance.
    /// Unless [`TuneSettings::full_grid`], each view's curve runs from the farthest grid distance in to the
    /// nearest that breaks the budget and stops there: the crossing, the dense check and the switch read nothing
    /// nearer (a view's break is within [`NEAR_BUDGET`] of the budget, so the grid's farthest close distance is
    /// the same), and the nearer distances are the costliest to draw (the model covers most of the frame).
    /// The worst excess stays 0 where no view was measured.
    pub(super) fn measure_views(&mut self, lod: u32, range: &DistanceRange) -> Result<Curves> {
        let (grid, near, budget) = (&range.grid, range.near, self.settings.budget);
        let full = self.settings.full_grid();
        let mut per_view = Vec::with_capacity(self.views.len());
        let mut worst: Vec<(f32, f64)> = grid.iter().map(|&d| (d, 0.0)).collect();
        for v in 0..self.views.len() {
            let mut measured = Vec::with_capacity(grid.len());
            for &d in grid.iter().rev() {
                let m = self.measure(lod, v, d)?;
                measured.push((d, m));
                if !full && budget.broken_by(m.value()) {
                    break;
                }
            }
            measured.reverse();
            let mut curve = Vec::with_capacity(measured.len());
            for (d, m) in measured {
                self.record(lod, v, d, range, m, false);
                curve.push((d, m.value()));
            }
            let skipped = grid.len() - curve.len();
            for (w, c) in worst[skipped..].iter_mut().zip(&curve) {
                w.1 = match budget {
                    Budget::Lodpop(_) => w.1.max(c.1),
                    Budget::Jod(_) => w.1.max(10.0 - c.1),
                };
            }
            per_view.push(
                match nearest_within(&curve, budget, |d| self.sample(lod, v, d, range, true))? {
                    Crossing::Everywhere => Some(near),
                    Crossing::From(d) => Some(d),
                    Crossing::Never => None,
                },
            );
        }
        Ok(Curves { per_view, worst })
    }

    /// The pair (`lod`, `lod + 1`)'s figure at view `v` and distance `d` ([`ModelTuning::measure`]), recorded as a
    /// sample (`refined`: a bisection step).
    fn sample(
        &mut self,
        lod: u32,
        v: usize,
        d: f32,
        range: &DistanceRange,
        refined: bool,
    ) -> Result<f64> {
        let m = self.measure(lod, v, d)?;
        self.record(lod, v, d, range, m, refined);
        Ok(m.value())
    }

    /// Appends the pair (`lod`, `lod + 1`)'s figures `m` at view `v` and distance `d` to the samples.
    fn record(
        &mut self,
        lod: u32,
        v: usize,
        d: f32,
        range: &DistanceRange,
        m: Measured,
        refined: bool,
    ) {
        let name = self.camera.scene.models[self.model as usize].name.clone();
        self.samples.push(Sample {
            model: name,
            lod_from: lod,
            lod_to: lod + 1,
            view: v as u32,
            distance: d,
            screen_size: range.screen(d),
            lodpop: m.lodpop,
            lodpop_coverage: m.coverage,
            lodpop_shading: m.shading,
            jod: m.jod,
            refined,
        });
    }

    /// Every view at the switch: the views whose crossing lies nearer are within the budget at every grid
    /// distance beyond theirs, but may break it between two; then the switch moves out to the next grid
    /// distance, where none does. The switch and the worst figure over the views there.
    pub(super) fn past_grid_breaks(
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
    pub(super) fn dense_check(
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
    pub(super) fn rules_at(
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
