//! What every generator makes: a [`ModelChain`] (a LOD chain and its colours), with each LOD's `error_abs`
//! measured against LOD0 in both directions ([`measure_error`]).

use crate::error::{Error, Result};
use crate::geometry::lod::LodChain;
use crate::geometry::mesh::Mesh;
use crate::geometry::morph::closest_surface;
use glam::Vec3;

/// The most LOD0 vertices the error measurement looks at (every k-th vertex, k = ceil(n / ERROR_SAMPLES)).
pub const ERROR_SAMPLES: usize = 2000;

/// A generated model: its LOD chain and one linear-RGB base colour per LOD (see the module docs).
#[derive(Debug, Clone)]
pub struct ModelChain {
    pub chain: LodChain,
    /// `lod_colors[k]` is the colour of an instance drawn at LOD k; as many entries as LODs.
    pub lod_colors: Vec<[f32; 3]>,
}

impl ModelChain {
    /// The colour of LOD `lod` (the last LOD's colour past the end).
    pub fn color(&self, lod: usize) -> [f32; 3] {
        self.lod_colors
            .get(lod)
            .or(self.lod_colors.last())
            .copied()
            .unwrap_or([1.0; 3])
    }
}

/// The largest distance from (a sample of) `fine`'s vertices to `coarse`'s surface: every k-th vertex,
/// k = ceil(vertices / max_samples), so at most `max_samples` vertices are looked at.
pub fn measure_error(fine: &Mesh, coarse: &Mesh, max_samples: usize) -> Result<f32> {
    let n = fine.positions.len();
    let stride = n.div_ceil(max_samples.max(1)).max(1);
    let sample: Vec<[f32; 3]> = fine.positions.iter().step_by(stride).copied().collect();
    let normals = vec![[0.0, 1.0, 0.0]; sample.len()];
    let probe = Mesh::new("error sample", sample, Some(normals), vec![0, 0, 0])?;
    let targets = closest_surface(&probe, coarse);
    Ok(probe
        .positions
        .iter()
        .zip(&targets.positions)
        .map(|(p, q)| Vec3::from(*p).distance(Vec3::from(*q)))
        .fold(0.0f32, f32::max))
}

/// `error_abs` for a chain: 0 for LOD0, then for each LOD the larger of [`measure_error`] from LOD0 to it and
/// from it to LOD0.
pub(super) fn measure_errors(meshes: &[Mesh]) -> Result<Vec<f32>> {
    let Some(lod0) = meshes.first() else {
        return Err(Error::Config("empty LOD chain".into()));
    };
    let mut out = vec![0.0];
    for m in &meshes[1..] {
        let forward = measure_error(lod0, m, ERROR_SAMPLES)?;
        let backward = measure_error(m, lod0, ERROR_SAMPLES)?;
        out.push(forward.max(backward));
    }
    Ok(out)
}
