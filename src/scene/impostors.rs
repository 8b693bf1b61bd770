//! `--impostor`: every model's chain ends in an octahedral impostor (`geometry/impostor.rs`), appended after the
//! family's builder made the chain. The impostor's card is a level like any other: the schedule switches to it
//! at its distance and every method draws it through the same entry points; the GPU bakes its atlas
//! (`gpu/impostor_atlas.rs`).

use crate::error::{Error, Result};
use crate::geometry::impostor::{card_mesh, Impostor, MAX_IMPOSTORS};
use crate::geometry::lod::Lod;
use crate::geometry::projection::switch_distance;
use crate::scene::model::{Model, SwitchSource};
use crate::scene::schedule::ScheduleParams;

/// What the impostor's switch is placed with: the pixel error, the viewport's height and the field of view.
pub struct SwitchView {
    pub pixel_error: f32,
    pub height: u32,
    pub fov_y: f32,
}

/// Appends the impostor level to every model but the ground: its card (slot = the model's place among those
/// with an impostor), its error and its switch distance (`--impostor-distance`, else where its error reaches
/// the pixel error; after the model's last switch either way). Returns a note per model.
pub fn append(
    models: &mut [Model],
    imp: &Impostor,
    view: &SwitchView,
    schedule: &ScheduleParams,
) -> Result<Vec<String>> {
    let mut notes = Vec::new();
    let mut slot = 0u32;
    for model in models.iter_mut() {
        if model.switch_source == SwitchSource::Ground {
            continue;
        }
        if slot as usize == MAX_IMPOSTORS {
            return Err(Error::Config(format!(
                "--impostor: the scene has more than {MAX_IMPOSTORS} models; impostors are built for at most \
                 {MAX_IMPOSTORS}: run without --impostor"
            )));
        }
        let radius_obj = model.radius / model.scale;
        if !(radius_obj.is_finite() && radius_obj > 0.0) {
            return Err(Error::Config(format!(
                "--impostor: model {} has no extent (bounding radius {radius_obj}); an impostor cannot be baked \
                 from it",
                model.name
            )));
        }
        let error_abs = imp.error_abs(radius_obj);
        let last = model.switches.last().copied();
        let own = switch_distance(
            error_abs,
            model.scale,
            view.pixel_error,
            view.height,
            view.fov_y,
        );
        let distance = match (imp.distance, last) {
            (Some(d), Some(l)) if d <= l => {
                return Err(Error::Config(format!(
                    "--impostor-distance {d}: model {}'s last mesh LOD switches at {l}; the impostor comes after \
                     it",
                    model.name
                )))
            }
            (Some(d), _) => d,
            (None, Some(l)) if own <= l * 1.0001 => l * 1.0001,
            (None, _) => own,
        };
        let material = model.chain.lods[0].mesh.parts.first().map(|p| p.material);
        let card = card_mesh(
            &format!("{}'s impostor", model.name),
            model.center,
            slot,
            material,
        )?;
        model.chain.lods.push(Lod {
            mesh: card,
            target_fraction: 0.0,
            error_abs,
        });
        model.switches.push(distance);
        if !model.lod_colors.is_empty() {
            // The impostor is LOD0's picture, in LOD0's colour.
            let c = model.color_of(0);
            model.lod_colors.push(c);
        }
        schedule.check_switches(&model.name, &model.switches)?;
        notes.push(format!(
            "{}: LOD{} is an impostor from distance {distance:.4} ({}; error {error_abs:.4} object units)",
            model.name,
            model.chain.lods.len() - 1,
            if imp.distance.is_some() {
                "--impostor-distance"
            } else {
                "its error at the pixel error"
            }
        ));
        slot += 1;
    }
    Ok(notes)
}
