//! The procedural scenes of Scherzer & Wimmer 2008, section 4: SIMPLE's sphere and box, WINDMILLS and TREES
//! (`crate::geometry::procgen`), many instances on a field under a camera flight.

use crate::error::Result;
use crate::geometry::lod;
use crate::geometry::procgen::{self, ModelChain};
use crate::geometry::projection::Sphere;
use crate::scene::config::SceneConfig;
use crate::scene::kind::SceneKind;
use crate::scene::model::{
    CameraTrack, Instance, Layout, Model, ModelSet, Motion, SwitchSource, SCENE_SEED,
};
use glam::Vec3;

/// Rotation of the windmill blades per frame, radians (one turn in 5 s at 60 fps).
pub const WINDMILL_SPIN_PER_FRAME: f32 = std::f32::consts::TAU / 300.0;

/// The model of procedural scene `kind`, built once: SIMPLE's sphere and box, the windmill, the tree.
/// Switch distances: from the measured LOD errors and `--pixel-error` like the bunny's, except SIMPLE, whose
/// box is no approximation of the sphere at any distance: it switches at 12 sphere radii (at 320x240 and 60
/// degrees the sphere is then about 17 pixels across), or at `--switch-distances`.
pub fn def(kind: SceneKind, cfg: &SceneConfig, height: u32, fov_y: f32) -> Result<ModelSet> {
    let started = std::time::Instant::now();
    let name = kind.name();
    let (chain, spin, source) = model_chain(kind)?;
    let lod_generation_ms = started.elapsed().as_secs_f64() * 1e3;
    let lod_colors = chain.lod_colors.clone();
    let chain = chain.chain;
    let Sphere {
        centre: center,
        radius,
    } = chain.lods[0].mesh.bounding_sphere();
    let scale = 1.0;
    let (switches, switch_source) = cfg.switches_or(
        name,
        (chain.lods.len(), radius * scale, fov_y),
        || match kind {
            SceneKind::Simple => (vec![12.0 * radius], SwitchSource::Scene),
            _ => (
                lod::switch_distances(&chain, scale, cfg.pixel_error(kind, height), height, fov_y),
                SwitchSource::PixelError,
            ),
        },
    )?;
    cfg.schedule.check_switches(name, &switches)?;
    let model = Model {
        name: name.trim_end_matches('s').to_string(),
        color: lod_colors.first().copied().unwrap_or([0.7; 3]),
        lod_colors,
        spin_per_frame: spin,
        chain,
        switches,
        switch_source,
        center,
        radius: radius * scale,
        scale,
        deformed_reach: None,
    };
    Ok(ModelSet {
        models: vec![model],
        mesh_source: source.to_string(),
        lod_generation_ms,
        notes: Vec::new(),
    })
}

/// The LOD chain of procedural scene `kind`'s model, its blades' spin per frame, and its `mesh_source`.
fn model_chain(kind: SceneKind) -> Result<(ModelChain, f32, &'static str)> {
    Ok(match kind {
        SceneKind::Simple => (
            procgen::simple_chain()?,
            0.0,
            "procedural (src/geometry/procgen.rs: sphere and box)",
        ),
        SceneKind::Windmills => (
            procgen::windmill_chain()?,
            WINDMILL_SPIN_PER_FRAME,
            "procedural (src/geometry/procgen.rs: windmill)",
        ),
        _ => (
            procgen::tree_chain(SCENE_SEED)?,
            0.0,
            "procedural (src/geometry/procgen.rs: tree, seed SCENE_SEED = 2008)",
        ),
    })
}

/// `count` instances of model `m` on a jittered square grid on the ground plane (spacing 2.5 model radii,
/// jitter +-0.3 spacing, random yaw; SCENE_SEED), and a camera flight along +z at a fixed height over the
/// middle of the field, looking 12 degrees down: it starts back from the field's near edge by 1.1 times the
/// last switch distance (so the nearest instances start at the coarsest LOD) and ends over the far edge, so
/// instances keep entering and leaving transitions.
pub fn layout(m: &Model, count: u32) -> Layout {
    let spacing = 2.5 * m.radius;
    let side = (count as f32).sqrt().ceil().max(1.0) as u32;
    let half = (side as f32 - 1.0) * spacing * 0.5;
    let mut rng = crate::rng::SplitMix64::new(SCENE_SEED ^ count as u64);
    let instances: Vec<Instance> = (0..count)
        .map(|i| {
            let (gx, gz) = ((i % side) as f32, (i / side) as f32);
            let jx = (rng.next_f32() - 0.5) * 0.6 * spacing;
            let jz = (rng.next_f32() - 0.5) * 0.6 * spacing;
            Instance {
                model: 0,
                // The bounding-sphere centre's height above the ground (the model's base sits at y = 0).
                position: Vec3::new(
                    gx * spacing - half + jx,
                    m.center.y,
                    gz * spacing - half + jz,
                ),
                yaw: rng.next_f32() * std::f32::consts::TAU,
                rotation: glam::Quat::IDENTITY,
                scale: Vec3::ONE,
            }
        })
        .collect();
    let last = m.switches.last().copied().unwrap_or(10.0 * m.radius);
    let height = 2.0 * m.radius + m.center.y;
    let rows = count.div_ceil(side) as f32;
    let z_far = (rows - 1.0) * spacing - half;
    let from = Vec3::new(0.0, height, -half - 1.1 * last);
    let to = Vec3::new(0.0, height, z_far);
    let pitch = 12f32.to_radians();
    let extent = (to - from).length() + 2.0 * half + 4.0 * m.radius + last;
    Layout {
        instances,
        motion: Motion::Static,
        near: m.radius * 0.02,
        far: extent * 1.5,
        eye: from,
        forward: Vec3::new(0.0, -pitch.sin(), pitch.cos()),
        track: Some(CameraTrack::Flight(from, to)),
        unified: None,
    }
}
