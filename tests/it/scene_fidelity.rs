//! Fidelity to a user's own mesh: the bunny scenes' path never puts the camera inside the model, switches it
//! cannot reach are said, and FSI's t-instances do not vanish when the camera is near or inside a model.

use crate::common::{render_frame, scene_config, static_scene};
use lodbench::scene::{SceneDef, SceneKind, NOT_REACHED};

/// A switch nearer than where the model fits the view is not reached by a sweep that starts there: the run
/// says which (a note, and describe's LOD), and the sweep starts past that switch's band.
#[test]
fn a_switch_nearer_than_the_fit_is_named_as_not_reached() {
    let probe = SceneDef::new(SceneKind::BunnySweep, &scene_config("bunny-sweep", &[])).unwrap();
    let fit = probe.path().unwrap().fit;
    let switches = format!("{},{},{}", fit * 0.5, fit * 2.0, fit * 4.0);
    let cfg = scene_config("bunny-sweep", &["--switch-distances", &switches]);
    let def = SceneDef::new(SceneKind::BunnySweep, &cfg).unwrap();
    let path = def.path().unwrap();
    assert_eq!(path.unreached, 1, "{path:?}");
    assert!(path.near > fit * 0.5 * 1.05, "{path:?}");
    let notes = def.notes();
    assert_eq!(notes.len(), 1, "{notes:?}");
    assert!(
        notes[0].contains(NOT_REACHED) && notes[0].contains("LOD1 at"),
        "{notes:?}"
    );
    let d = def.describe(&cfg);
    assert_eq!(d.models[0].lods[1].note, Some(NOT_REACHED));
    assert_eq!(d.models[0].lods[2].note, None);
}

/// With the camera inside the bunny (at 2 % of its radius from the bounding-sphere centre, which lies inside
/// its body), every pixel the reference shows is the bunny's inside, drawn two-sided. FSI's t-instance at k =
/// 0.5 must show it too: at most 1 % of the reference's covered pixels may be background in FSI's frame. With
/// back faces culled (FSI's earlier choice) nearly all of them were.
#[test]
fn fsi_t_instances_show_the_inside_like_the_reference() {
    let ctx = crate::common::gpu();
    let probe = static_scene(&[1.0], [1.0, 2.0, 3.0], 3, "fixed");
    let d = probe.models[0].radius * 0.02;
    let mut scene = static_scene(&[d], [d, 2.0 * d, 3.0 * d], 3, "fixed");
    scene.far = 4.0 * probe.models[0].radius;
    let (reference, fsi) = (
        render_frame(&ctx, &scene, "reference", 2),
        render_frame(&ctx, &scene, "fsi", 2),
    );
    let bg = |p: &[u8]| p[..3] == [60, 63, 69];
    let covered = reference.chunks_exact(4).filter(|p| !bg(p)).count();
    let lost = reference
        .chunks_exact(4)
        .zip(fsi.chunks_exact(4))
        .filter(|(a, b)| !bg(a) && bg(b))
        .count();
    assert!(
        covered * 2 > reference.len() / 4,
        "the reference covers only {covered} pixels: the camera is not inside"
    );
    assert!(
        lost * 100 <= covered,
        "fsi shows background on {lost} of the {covered} pixels the reference covers"
    );
}
