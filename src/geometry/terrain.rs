//! The `terrain` scene's mesh: a procedural heightfield, one large connected mesh for block LOD (Blow 2003a
//! and 2003b) and cluster LOD to divide. Pure CPU, deterministic.
//!
//! - A square of side [`TERRAIN_SIZE`] world units on the x-z plane (x, z in [0, size]), y up, sampled on a
//!   regular grid of `quads` x `quads` cells, two triangles per cell (the diagonal from (i, j) to
//!   (i + 1, j + 1)), wound counter-clockwise seen from above; normals are the area-weighted vertex normals.
//! - Height: fractal value noise, [`OCTAVES`] octaves, each of half the amplitude and twice the frequency of
//!   the one before, the first with a wavelength of [`BASE_WAVELENGTH`] units; summed and scaled so the
//!   heights span about [0, [`TERRAIN_RELIEF`]]. Value noise: a lattice of values in [-1, 1] from
//!   [`crate::rng::SplitMix64`] seeded by `seed`, the octave and the lattice point, interpolated with the
//!   quintic fade `6t^5 - 15t^4 + 10t^3`. The scene's seed is [`crate::scene::SCENE_SEED`].
//!
//! Triangle counts: `2 quads^2` (the profiles in `scene/kind.rs`: 1,000 quads a side at the paper profile,
//! 2,000,000 triangles; 280 at ci, 156,800; 160 at quick, 51,200; 48 at regress, 4,608).

use crate::error::Result;
use crate::geometry::mesh::Mesh;
use crate::rng::SplitMix64;

/// Side of the terrain square, world units.
pub const TERRAIN_SIZE: f32 = 100.0;
/// Height range of the terrain, world units (about; the noise sum is scaled to it).
pub const TERRAIN_RELIEF: f32 = 12.0;
/// Wavelength of the first octave, world units.
pub const BASE_WAVELENGTH: f32 = 40.0;
/// Octaves of the noise.
pub const OCTAVES: u32 = 6;

/// The procedural terrain's height field as ROAM and `blocks-tree` take it: the scene's seed, the mesh's cells a
/// side and the blocks along a side.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct TerrainField {
    pub seed: u64,
    pub quads: u32,
    /// Blocks along a side (`--blocks`): the leaves of `blocks-tree`.
    pub blocks: u32,
}

/// A lattice value in [-1, 1] for point (i, j) of `octave`.
fn lattice(seed: u64, octave: u32, i: i64, j: i64) -> f32 {
    let h = seed
        ^ (octave as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15)
        ^ (i as u64).wrapping_mul(0xC2B2_AE3D_27D4_EB4F)
        ^ (j as u64).wrapping_mul(0x1656_67B1_9E37_79F9);
    SplitMix64::new(h).next_f32() * 2.0 - 1.0
}

fn fade(t: f32) -> f32 {
    t * t * t * (t * (t * 6.0 - 15.0) + 10.0)
}

/// Value noise of one octave at (x, z) in lattice units.
fn value_noise(seed: u64, octave: u32, x: f32, z: f32) -> f32 {
    let (ix, iz) = (x.floor(), z.floor());
    let (fx, fz) = (fade(x - ix), fade(z - iz));
    let (i, j) = (ix as i64, iz as i64);
    let v = |di: i64, dj: i64| lattice(seed, octave, i + di, j + dj);
    let a = v(0, 0) + (v(1, 0) - v(0, 0)) * fx;
    let b = v(0, 1) + (v(1, 1) - v(0, 1)) * fx;
    a + (b - a) * fz
}

/// The terrain's height at (x, z), world units.
pub fn height(seed: u64, x: f32, z: f32) -> f32 {
    let mut sum = 0.0;
    let mut amplitude = 1.0;
    let mut norm = 0.0;
    let mut frequency = 1.0 / BASE_WAVELENGTH;
    for octave in 0..OCTAVES {
        sum += amplitude * value_noise(seed, octave, x * frequency, z * frequency);
        norm += amplitude;
        amplitude *= 0.5;
        frequency *= 2.0;
    }
    // sum / norm is in [-1, 1], mostly within +-0.6: map that to [0, relief].
    (sum / norm / 0.6 * 0.5 + 0.5) * TERRAIN_RELIEF
}

/// The heightfield mesh of `quads` x `quads` cells (at least 1).
pub fn terrain_mesh(seed: u64, quads: u32) -> Result<Mesh> {
    let n = quads.max(1);
    let row = n + 1;
    let step = TERRAIN_SIZE / n as f32;
    let mut positions = Vec::with_capacity((row * row) as usize);
    for j in 0..row {
        for i in 0..row {
            let (x, z) = (i as f32 * step, j as f32 * step);
            positions.push([x, height(seed, x, z), z]);
        }
    }
    let mut indices = Vec::with_capacity((n * n * 6) as usize);
    for j in 0..n {
        for i in 0..n {
            let a = j * row + i;
            let (b, c, d) = (a + 1, a + row + 1, a + row);
            // Counter-clockwise seen from +y: (a, c, b) and (a, d, c).
            indices.extend_from_slice(&[a, c, b, a, d, c]);
        }
    }
    Mesh::new("terrain (procedural)", positions, None, indices)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn terrain_is_deterministic_faces_up_and_spans_its_relief() {
        let a = terrain_mesh(2008, 40).unwrap();
        let b = terrain_mesh(2008, 40).unwrap();
        assert_eq!(a, b);
        assert_ne!(a, terrain_mesh(7, 40).unwrap());
        assert_eq!(a.triangle_count(), 2 * 40 * 40);
        assert!(a.normals.iter().all(|n| n[1] > 0.0));
        let (lo, hi) = a.bounds();
        assert_eq!(
            (lo.x, lo.z, hi.x, hi.z),
            (0.0, 0.0, TERRAIN_SIZE, TERRAIN_SIZE)
        );
        let relief = hi.y - lo.y;
        assert!(
            relief > 0.4 * TERRAIN_RELIEF && relief < 1.6 * TERRAIN_RELIEF,
            "{relief}"
        );
    }

    #[test]
    fn noise_is_continuous_across_lattice_cells() {
        for x in [0.999_f32, 3.9999, 10.0] {
            let (l, r) = (
                height(1, x * BASE_WAVELENGTH - 1e-3, 5.0),
                height(1, x * BASE_WAVELENGTH + 1e-3, 5.0),
            );
            assert!((l - r).abs() < 0.01, "{l} {r}");
        }
    }
}
