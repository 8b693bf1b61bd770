//! FSI's arithmetic on the CPU: tau of eq. 1 (Fig. 2) and its margin, the toggle of a t-instance between its two
//! LODs frame by frame, the ids its faces write, and eq. 2's reprojection (Scherzer & Wimmer 2008 sections 3.2-3.4).

use crate::scene::schedule::InstanceState;
use crate::scene::Camera;
use glam::{DMat4, Mat4};

/// `fsi-blend`'s weight of LOD `lod` of a t-instance in state `s`: k for the incoming LOD, 1 - k for the
/// outgoing one (the two buffers' weights at one k add up to 1).
pub fn blend_weight(s: &InstanceState, lod: u32) -> f32 {
    if lod == s.lod_to {
        s.k
    } else {
        1.0 - s.k
    }
}

/// tau of eq. 1 for LOD `lod` of a t-instance in state `s` (Fig. 2): the incoming LOD fades in over the first
/// half of the transition, the outgoing one fades out over the second.
pub fn tau(s: &InstanceState, lod: u32) -> f32 {
    tau_with_margin(s, lod, 0.0)
}

/// [`tau`] with the midpoint plateau, where both LODs are complete, widened by `margin` on each side:
/// tau_to = min(1, 2 (k + margin)), tau_from = min(1, 2 (1 - k + margin)). FSI passes the instance's change of
/// k since the previous frame: the older buffer was rendered with the previous k, and without the margin a
/// frame whose k steps across 0.5 combines two buffers that both have holes (the visibility texture is the
/// same for both LODs, so the holes coincide and the background shows through for a frame).
pub fn tau_with_margin(s: &InstanceState, lod: u32, margin: f32) -> f32 {
    let t = if lod == s.lod_to {
        2.0 * (s.k + margin)
    } else {
        2.0 * (1.0 - s.k + margin)
    };
    // k comes from distances and carries rounding: at the midpoint both LODs must be complete.
    if t >= 1.0 - 1e-5 {
        1.0
    } else {
        t
    }
}

/// The LOD a t-instance starts its toggle with: the one complete (tau = 1) when the transition is entered.
pub fn first_lod(s: &InstanceState) -> u32 {
    if s.k < 0.5 {
        s.lod_from
    } else {
        s.lod_to
    }
}

/// The LOD a t-instance shows `phase` frames after its transition started (its toggle counter), `first` being
/// the LOD it started with: `first` on even phases, the other on odd ones.
pub fn toggle_lod(s: &InstanceState, first: u32, phase: i64) -> u32 {
    let other = if first == s.lod_from {
        s.lod_to
    } else {
        s.lod_from
    };
    if phase.rem_euclid(2) == 0 {
        first
    } else {
        other
    }
}

/// Which LOD each t-instance shows in a buffer.
#[derive(Debug, Clone, Copy)]
pub(super) enum Toggle {
    /// The toggle counter at this frame (frame-sequential variants).
    AtFrame(u32),
    /// `lod_from` in buffer 0, `lod_to` in buffer 1 (`fsi-sameframe`).
    Buffer(u32),
}

/// P_old V_old V_new^-1 P_new^-1 (eq. 2), computed in f64 so that a still camera gives the identity.
pub fn reprojection(new: &Camera, old: &Camera) -> Mat4 {
    let d = |m: Mat4| DMat4::from_cols_array(&m.to_cols_array().map(|x| x as f64));
    let m = d(old.proj) * d(old.view) * d(new.view).inverse() * d(new.proj).inverse();
    Mat4::from_cols_array(&m.to_cols_array().map(|x| x as f32))
}

/// The id a t-instance's front faces write (its back faces write one more, [`back_id`]); 0 is the n-instances'.
pub fn front_id(instance: usize) -> u32 {
    2 * instance as u32 + 1
}

/// The id a t-instance's back faces write: [`front_id`] + 1.
pub fn back_id(instance: usize) -> u32 {
    front_id(instance) + 1
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::{Vec3, Vec4};

    fn st(from: u32, to: u32, k: f32) -> InstanceState {
        InstanceState {
            lod_from: from,
            lod_to: to,
            k,
        }
    }

    #[test]
    fn tau_follows_figure_2() {
        // Incoming LOD fades in over the first half, outgoing fades out over the second.
        let s = st(0, 1, 0.25);
        assert_eq!(tau(&s, 1), 0.5);
        assert_eq!(tau(&s, 0), 1.0);
        let s = st(0, 1, 0.5);
        assert_eq!((tau(&s, 0), tau(&s, 1)), (1.0, 1.0));
        let s = st(0, 1, 0.75);
        assert_eq!((tau(&s, 0), tau(&s, 1)), (0.5, 1.0));
    }

    #[test]
    fn margin_keeps_one_buffer_complete_across_the_midpoint() {
        // k steps 0.48 -> 0.52: the older buffer holds lod_to at k = 0.48, the newer lod_from at k = 0.52.
        let (old, new) = (st(0, 1, 0.48), st(0, 1, 0.52));
        assert!(tau(&old, 1) < 1.0 && tau(&new, 0) < 1.0);
        let m = 0.04;
        assert!(tau_with_margin(&old, 1, m) == 1.0 || tau_with_margin(&new, 0, m) == 1.0);
    }

    #[test]
    fn toggle_starts_with_the_outgoing_lod_and_alternates() {
        let s = st(2, 3, 0.1);
        assert_eq!(first_lod(&s), 2);
        assert_eq!(toggle_lod(&s, 2, 0), 2);
        assert_eq!(toggle_lod(&s, 2, 1), 3);
        assert_eq!(toggle_lod(&s, 2, 2), 2);
        assert_eq!(toggle_lod(&s, 2, -1), 3);
        // Entered from the far end (k falling from 1): the complete LOD is lod_to.
        let s = st(2, 3, 0.95);
        assert_eq!(first_lod(&s), 3);
        assert_eq!(toggle_lod(&s, 3, 0), 3);
        assert_eq!(toggle_lod(&s, 3, 1), 2);
    }

    #[test]
    fn reprojection_of_a_still_camera_is_the_identity() {
        let c = Camera {
            eye: Vec3::new(1.0, 2.0, 3.0),
            view: Mat4::look_at_rh(Vec3::new(1.0, 2.0, 3.0), Vec3::ZERO, Vec3::Y),
            proj: Mat4::perspective_rh(0.8, 1.5, 0.1, 100.0),
        };
        let m = reprojection(&c, &c);
        assert!(m.abs_diff_eq(Mat4::IDENTITY, 1e-6), "{m}");
    }

    #[test]
    fn reprojection_maps_a_world_point_between_frames() {
        let proj = Mat4::perspective_rh(0.8, 1.5, 0.1, 100.0);
        let cam = |eye: Vec3| Camera {
            eye,
            view: Mat4::look_at_rh(eye, Vec3::new(0.0, 0.0, -10.0), Vec3::Y),
            proj,
        };
        let (new, old) = (cam(Vec3::new(0.5, 0.0, 0.0)), cam(Vec3::ZERO));
        let world = Vec4::new(0.7, -0.4, -8.0, 1.0);
        let clip_new = new.proj * new.view * world;
        let clip_old = old.proj * old.view * world;
        let p_new = clip_new / clip_new.w;
        let p = reprojection(&new, &old) * p_new;
        let p_old = p / p.w;
        assert!((p_old - clip_old / clip_old.w).abs().max_element() < 1e-5);
    }
}
