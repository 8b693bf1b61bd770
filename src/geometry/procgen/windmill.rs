//! WINDMILLS: a tower, a nacelle, a spinner and four twisted blades, 4 LODs from coarser parameters (the
//! module docs of `procgen` give the table).

use super::mesh_builder::{loft, tube, AuxKind, Builder, Caps};
use super::model_chain::{measure_errors, ModelChain};
use crate::error::Result;
use crate::geometry::lod::LodChain;
use crate::geometry::mesh::{Mesh, AUX_BLADE, AUX_SOLID};
use glam::Vec3;
use std::f32::consts::{PI, TAU};

/// Rotor hub height of the windmill (the blade rotation axis is parallel to +z through (0, hub_y)).
pub const WINDMILL_HUB_Y: f32 = 7.0;
/// Blade tip radius from the hub axis.
pub const WINDMILL_ROTOR_RADIUS: f32 = 3.0;
/// The z of the plane the blades' pitch axes lie in (in front of the nacelle, which ends at z = 0.6).
pub const WINDMILL_BLADE_Z: f32 = 0.8;

/// Per-LOD generation parameters of the windmill (see the module docs' table).
#[derive(Debug, Clone, Copy)]
struct WindmillParams {
    tower: (usize, usize),
    nacelle: (usize, usize),
    spinner: (usize, usize),
    blade: (usize, usize),
}

const WINDMILL_LODS: [WindmillParams; 4] = [
    WindmillParams {
        tower: (64, 41),
        nacelle: (32, 20),
        spinner: (32, 10),
        blade: (32, 43),
    },
    WindmillParams {
        tower: (32, 17),
        nacelle: (16, 10),
        spinner: (16, 6),
        blade: (16, 23),
    },
    WindmillParams {
        tower: (12, 6),
        nacelle: (8, 5),
        spinner: (8, 3),
        blade: (8, 12),
    },
    WindmillParams {
        tower: (8, 2),
        nacelle: (4, 3),
        spinner: (3, 2),
        blade: (4, 2),
    },
];

/// WINDMILLS: 4 LODs of 18,086 / 4,486 / 1,002 / 98 triangles, about 10 units tall, facing +z, rotor hub at
/// (0, [`WINDMILL_HUB_Y`]).
pub fn windmill_chain() -> Result<ModelChain> {
    let meshes = WINDMILL_LODS
        .iter()
        .enumerate()
        .map(|(k, p)| windmill_mesh(&format!("windmill/lod{k}"), p))
        .collect::<Result<Vec<_>>>()?;
    let errors = measure_errors(&meshes)?;
    Ok(ModelChain {
        chain: LodChain::from_meshes("windmill", meshes, &errors)?,
        lod_colors: vec![[0.78, 0.78, 0.74]; WINDMILL_LODS.len()],
    })
}

fn windmill_mesh(name: &str, p: &WindmillParams) -> Result<Mesh> {
    let mut b = Builder::default();
    let hub = WINDMILL_HUB_Y;
    let solid = AuxKind::new(AUX_SOLID, 0.0);
    let blade = AuxKind::new(AUX_BLADE, hub);

    // Tower: a frustum from the ground into the nacelle, capped on top.
    let (sides, rings) = p.tower;
    let top = hub - 0.1;
    let path: Vec<Vec3> = (0..rings)
        .map(|i| Vec3::new(0.0, top * i as f32 / (rings - 1) as f32, 0.0))
        .collect();
    let radii: Vec<f32> = (0..rings)
        .map(|i| 0.35 + (0.18 - 0.35) * i as f32 / (rings - 1) as f32)
        .collect();
    tube(&mut b, &path, &radii, sides, solid, Caps::End, false)?;

    // Nacelle: a capsule-like lathe along z.
    let (sides, rings) = p.nacelle;
    let (z0, z1) = (-0.9f32, 0.6f32);
    let path: Vec<Vec3> = (0..rings)
        .map(|i| Vec3::new(0.0, hub, z0 + (z1 - z0) * i as f32 / (rings - 1) as f32))
        .collect();
    let radii: Vec<f32> = (0..rings)
        .map(|i| {
            let s = 2.0 * i as f32 / (rings - 1) as f32 - 1.0; // -1..1
            0.3 * (1.0 - s.abs().powi(4)).max(0.0).powf(0.25).max(0.45)
        })
        .collect();
    tube(&mut b, &path, &radii, sides, solid, Caps::Both, false)?;

    // Spinner: a pointed cone in front of the nacelle; turns with the blades.
    let (sides, rings) = p.spinner;
    let (z0, z1) = (0.6f32, 1.1f32);
    let path: Vec<Vec3> = (0..rings)
        .map(|i| Vec3::new(0.0, hub, z0 + (z1 - z0) * i as f32 / (rings - 1) as f32))
        .collect();
    let radii: Vec<f32> = (0..rings)
        .map(|i| {
            let s = i as f32 / (rings - 1) as f32;
            (0.28 * (1.0 - s * s)).max(0.03)
        })
        .collect();
    tube(&mut b, &path, &radii, sides, blade, Caps::Both, false)?;

    // Blades.
    let (points, sections) = p.blade;
    for k in 0..4 {
        let theta = PI / 2.0 + k as f32 * PI / 2.0;
        windmill_blade(&mut b, theta, points, sections, blade)?;
    }
    b.finish(name)
}

/// One twisted, tapered blade pointing along angle `theta` (in the xy plane) from the hub.
fn windmill_blade(
    b: &mut Builder,
    theta: f32,
    points: usize,
    sections: usize,
    kind: AuxKind,
) -> Result<()> {
    let hub = Vec3::new(0.0, WINDMILL_HUB_Y, WINDMILL_BLADE_Z);
    let d = Vec3::new(theta.cos(), theta.sin(), 0.0);
    let travel = Vec3::new(-theta.sin(), theta.cos(), 0.0);
    let (r0, r1) = (0.15f32, WINDMILL_ROTOR_RADIUS);
    let mut rings = Vec::with_capacity(sections);
    for i in 0..sections {
        let s = i as f32 / (sections - 1).max(1) as f32;
        let r = r0 + (r1 - r0) * s;
        // Chord rises from the root to 20 % span, then tapers to the tip.
        let chord = if s < 0.2 {
            0.25 + (0.5 - 0.25) * s / 0.2
        } else {
            0.5 + (0.12 - 0.5) * (s - 0.2) / 0.8
        };
        let thickness = 0.24 + (0.12 - 0.24) * s;
        let twist = (20.0 + (2.0 - 20.0) * s).to_radians();
        let c_dir = travel * twist.cos() + Vec3::Z * twist.sin();
        let t_dir = d.cross(c_dir);
        let centre = hub + d * r;
        let ring: Vec<Vec3> = (0..points)
            .map(|j| {
                let a = j as f32 / points as f32 * TAU;
                let x = 0.5 * (1.0 + a.cos()); // 0 = leading edge, 1 = trailing edge
                let half = naca_half_thickness(x, thickness);
                let y = if a.sin() >= 0.0 { half } else { -half };
                centre + c_dir * ((x - 0.25) * chord) + t_dir * (y * chord)
            })
            .collect();
        rings.push(ring);
    }
    loft(b, &rings, kind, Caps::Both, -d, d)
}

/// Half thickness (in chords) of a symmetric NACA 00xx section at chord position x in [0, 1].
fn naca_half_thickness(x: f32, t: f32) -> f32 {
    let x = x.clamp(0.0, 1.0);
    5.0 * t
        * (0.2969 * x.sqrt() - 0.1260 * x - 0.3516 * x * x + 0.2843 * x.powi(3)
            - 0.1015 * x.powi(4))
}
