//! The mesh builder the generators share: a [`Builder`] of positions, normals and aux, and the shapes drawn
//! into it (tubes, lofts, UV spheres, flat boxes).

use crate::error::{Error, Result};
use crate::geometry::mesh::{vertex_normals, Mesh, AUX_SOLID};
use glam::{Quat, Vec3};
use std::f32::consts::{PI, TAU};

// ---------------------------------------------------------------------------------------------------------
// Mesh building

#[derive(Default)]
pub(super) struct Builder {
    positions: Vec<[f32; 3]>,
    /// Explicit normals; `[0, 0, 0]` = take the area-weighted vertex normal at `finish`.
    normals: Vec<[f32; 3]>,
    aux: Vec<[f32; 4]>,
    indices: Vec<u32>,
}

impl Builder {
    pub(super) fn vertex(&mut self, p: Vec3, n: Option<Vec3>, aux: [f32; 4]) -> u32 {
        let i = self.positions.len() as u32;
        self.positions.push(p.to_array());
        self.normals.push(n.map_or([0.0; 3], |n| n.to_array()));
        self.aux.push(aux);
        i
    }

    fn tri(&mut self, a: u32, b: u32, c: u32) {
        self.indices.extend_from_slice(&[a, b, c]);
    }

    pub(super) fn quad(&mut self, a: u32, b: u32, c: u32, d: u32) {
        self.tri(a, b, c);
        self.tri(a, c, d);
    }

    pub(super) fn finish(self, name: &str) -> Result<Mesh> {
        let computed = vertex_normals(&self.positions, &self.indices);
        let normals = self
            .normals
            .iter()
            .zip(computed)
            .map(|(n, c)| if *n == [0.0; 3] { c } else { *n })
            .collect();
        Mesh::new(name, self.positions, Some(normals), self.indices)?.with_aux(name, self.aux)
    }
}

#[derive(Debug, Clone, Copy)]
pub(super) struct AuxKind {
    kind: f32,
    hub_y: f32,
}

impl AuxKind {
    pub(super) fn new(kind: f32, hub_y: f32) -> Self {
        AuxKind { kind, hub_y }
    }

    fn at(&self, u: f32, v: f32) -> [f32; 4] {
        [u, v, self.kind, self.hub_y]
    }
}

#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) enum Caps {
    None,
    End,
    Both,
}

/// A generalised cylinder along `path` (parallel-transport frames), `sides` vertices per ring; with
/// `flat_start` the first ring is horizontal (its tangent is +y).
pub(super) fn tube(
    b: &mut Builder,
    path: &[Vec3],
    radii: &[f32],
    sides: usize,
    kind: AuxKind,
    caps: Caps,
    flat_start: bool,
) -> Result<()> {
    if path.len() < 2 || radii.len() != path.len() || sides < 3 {
        return Err(Error::Config(format!(
            "procgen tube with {} points, {} radii, {sides} sides",
            path.len(),
            radii.len()
        )));
    }
    let n = path.len();
    let tangent = |i: usize| {
        if i == 0 && flat_start {
            return Vec3::Y;
        }
        let (a, c) = (path[i.saturating_sub(1)], path[(i + 1).min(n - 1)]);
        (c - a).normalize_or(Vec3::Y)
    };
    let mut t = tangent(0);
    let mut normal = t.any_orthonormal_vector();
    let mut rings = Vec::with_capacity(n);
    for (i, (&p, &r)) in path.iter().zip(radii).enumerate() {
        let ti = tangent(i);
        normal = (Quat::from_rotation_arc(t, ti) * normal)
            .reject_from(ti)
            .normalize_or(ti.any_orthonormal_vector());
        t = ti;
        let bin = t.cross(normal);
        let phase = PI / sides as f32;
        rings.push(
            (0..sides)
                .map(|j| {
                    let a = j as f32 / sides as f32 * TAU + phase;
                    p + (normal * a.cos() + bin * a.sin()) * r
                })
                .collect::<Vec<_>>(),
        );
    }
    let start_n = -tangent(0);
    let end_n = tangent(n - 1);
    loft(b, &rings, kind, caps, start_n, end_n)
}

/// Connects closed rings of equal length (each counter-clockwise seen from the next ring) into a smooth
/// surface; caps are flat fans with their own vertices (normals `start_n`, `end_n`).
pub(super) fn loft(
    b: &mut Builder,
    rings: &[Vec<Vec3>],
    kind: AuxKind,
    caps: Caps,
    start_n: Vec3,
    end_n: Vec3,
) -> Result<()> {
    let m = rings.first().map_or(0, Vec::len);
    if rings.len() < 2 || m < 3 || rings.iter().any(|r| r.len() != m) {
        return Err(Error::Config(format!(
            "procgen loft with {} rings of {m} points",
            rings.len()
        )));
    }
    let last = rings.len() - 1;
    let first_id = b.positions.len() as u32;
    for (i, ring) in rings.iter().enumerate() {
        for (j, p) in ring.iter().enumerate() {
            b.vertex(
                *p,
                None,
                kind.at(j as f32 / m as f32, i as f32 / last as f32),
            );
        }
    }
    let id = |i: usize, j: usize| first_id + (i * m + j % m) as u32;
    for i in 0..last {
        for j in 0..m {
            b.quad(id(i, j), id(i, j + 1), id(i + 1, j + 1), id(i + 1, j));
        }
    }
    let mut cap = |ring: &[Vec3], n: Vec3, v: f32, flip: bool| {
        let ids: Vec<u32> = ring
            .iter()
            .enumerate()
            .map(|(j, p)| b.vertex(*p, Some(n), kind.at(j as f32 / m as f32, v)))
            .collect();
        for j in 1..m - 1 {
            if flip {
                b.tri(ids[0], ids[j + 1], ids[j]);
            } else {
                b.tri(ids[0], ids[j], ids[j + 1]);
            }
        }
    };
    if caps == Caps::Both {
        cap(&rings[0], start_n, 0.0, true);
    }
    if caps != Caps::None {
        cap(&rings[last], end_n, 1.0, false);
    }
    Ok(())
}

pub(super) fn uv_sphere(b: &mut Builder, centre: Vec3, r: f32, slices: usize, stacks: usize) {
    let solid = AuxKind::new(AUX_SOLID, 0.0);
    let first = b.positions.len() as u32;
    for i in 0..=stacks {
        let v = i as f32 / stacks as f32;
        let polar = v * PI;
        for j in 0..=slices {
            let u = j as f32 / slices as f32;
            let az = u * TAU;
            let n = Vec3::new(polar.sin() * az.cos(), polar.cos(), -polar.sin() * az.sin());
            b.vertex(centre + n * r, Some(n), solid.at(u, v));
        }
    }
    let row = (slices + 1) as u32;
    for i in 0..stacks as u32 {
        for j in 0..slices as u32 {
            let (a, c) = (first + i * row + j, first + (i + 1) * row + j);
            if i != 0 {
                b.tri(a, c, a + 1);
            }
            if i + 1 != stacks as u32 {
                b.tri(a + 1, c, c + 1);
            }
        }
    }
}

/// An axis-aligned box with 4 vertices per face (flat normals).
pub(super) fn flat_box(b: &mut Builder, centre: Vec3, half: Vec3) {
    let solid = AuxKind::new(AUX_SOLID, 0.0);
    for axis in [Vec3::X, Vec3::Y, Vec3::Z] {
        for sign in [1.0f32, -1.0] {
            let n = axis * sign;
            let u_dir = n.any_orthonormal_vector();
            let v_dir = n.cross(u_dir);
            let c = centre + n * half;
            let corner = |su: f32, sv: f32| c + (u_dir * su + v_dir * sv) * half;
            let ids = [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)].map(|(su, sv)| {
                b.vertex(
                    corner(su, sv),
                    Some(n),
                    solid.at(0.5 * (su + 1.0), 0.5 * (sv + 1.0)),
                )
            });
            b.quad(ids[0], ids[1], ids[2], ids[3]);
        }
    }
}
