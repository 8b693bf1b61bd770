//! SIMPLE: a red UV sphere and a blue box (the module docs of `procgen` give the table).

use super::mesh_builder::{flat_box, uv_sphere, Builder};
use super::model_chain::{measure_errors, ModelChain};
use crate::error::Result;
use crate::geometry::lod::LodChain;
use glam::Vec3;

/// SIMPLE: LOD0 a red UV sphere (radius 1, 1,472 triangles), LOD1 a blue flat-shaded box (side 1.6,
/// 12 triangles), both centred at (0, 1, 0).
pub fn simple_chain() -> Result<ModelChain> {
    let centre = Vec3::new(0.0, 1.0, 0.0);
    let mut b = Builder::default();
    uv_sphere(&mut b, centre, 1.0, 32, 24);
    let sphere = b.finish("simple/lod0")?;
    let mut b = Builder::default();
    flat_box(&mut b, centre, Vec3::splat(0.8));
    let cube = b.finish("simple/lod1")?;
    let meshes = vec![sphere, cube];
    let errors = measure_errors(&meshes)?;
    Ok(ModelChain {
        chain: LodChain::from_meshes("simple", meshes, &errors)?,
        lod_colors: vec![[0.8, 0.04, 0.03], [0.03, 0.08, 0.8]],
    })
}
