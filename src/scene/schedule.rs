//! The LOD schedule shared by every method: per instance per frame `(lod_from, lod_to, k)`.
//!
//! Selection is by distance against each model's switch distances (Sheliemietiev et al. 2023, section 8:
//! transitions happen in a small band around the switch distance, 0.95-1.05). Methods never select LODs
//! themselves; they only decide how to draw a state, so every method sees the same transitions on the same
//! frames.

use crate::effects::shadow::{Caster, ShadowLod};
use crate::error::{Error, Result};
use serde::Serialize;

/// How k advances during a transition.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, serde::Deserialize, clap::ValueEnum)]
#[serde(rename_all = "lowercase")]
pub enum FadeMode {
    /// k is the instance's position inside the band `[s(1-band), s(1+band)]` around switch distance s.
    Distance,
    /// k advances by 1/fade_frames per frame once the selected LOD changes, whatever the camera does.
    Time,
}

#[derive(Debug, Clone, Copy, Serialize)]
pub struct ScheduleParams {
    pub fade: FadeMode,
    /// Half-width of the transition band as a fraction of the switch distance (0.05 = 0.95-1.05).
    pub band: f32,
    /// Frames a time-based fade lasts.
    pub fade_frames: u32,
    /// Hysteresis margin as a fraction of the switch distance: coarsening happens around s(1+h), refining
    /// around s(1-h). 0 = plain thresholds, as in the papers.
    pub hysteresis: f32,
    /// `--max-transitions`: at most this many instances in transition at once (0: no cap; time fades only).
    /// An instance whose LOD should change while the cap is reached keeps its LOD, waiting, until a fade ends
    /// (Sheliemietiev et al. 2023 section 8: a steadier frame rate at the cost of a delay).
    #[serde(default)]
    pub max_transitions: u32,
}

impl Default for ScheduleParams {
    fn default() -> Self {
        ScheduleParams {
            fade: FadeMode::Distance,
            band: 0.05,
            fade_frames: 30,
            hysteresis: 0.0,
            max_transitions: 0,
        }
    }
}

impl ScheduleParams {
    /// A user's glTF file's defaults: a time fade of 8 frames. Its default flight crosses a switch's distance
    /// band in about one frame, where no blend can act; over 8 frames (133 ms at 60 frames a second) a blend
    /// changes the frame by about an eighth of the hard switch a frame, well within the answer's default budget
    /// (half the hard switch's), and the quick profile's 60 frames hold a 4-level chain's three fades. Engines
    /// fade longer (Unity's LODGroup.crossFadeAnimationDuration is 0.5 s): `--fade-frames 30` on a longer path.
    pub const FOR_USER_FILES: ScheduleParams = ScheduleParams {
        fade: FadeMode::Time,
        band: 0.05,
        fade_frames: 8,
        hysteresis: 0.0,
        max_transitions: 0,
    };

    pub fn validate(&self) -> Result<()> {
        if !(0.0..0.5).contains(&self.band) {
            return Err(Error::Config(format!(
                "--band {} must be in [0, 0.5)",
                self.band
            )));
        }
        if !(0.0..0.5).contains(&self.hysteresis) {
            return Err(Error::Config(format!(
                "--hysteresis {} must be in [0, 0.5)",
                self.hysteresis
            )));
        }
        if self.fade_frames == 0 {
            return Err(Error::Config("--fade-frames must be at least 1".into()));
        }
        if self.max_transitions > 0 && self.fade != FadeMode::Time {
            return Err(Error::Config(format!(
                "--max-transitions {} needs --fade time: a distance fade's k is the instance's place in its band, \
                 so holding an instance back would end in a pop",
                self.max_transitions
            )));
        }
        Ok(())
    }

    /// Checks that the bands of consecutive switch distances do not overlap, so an instance is never in two
    /// transitions at once.
    pub fn check_switches(&self, model: &str, switches: &[f32]) -> Result<()> {
        if let Some(bad) = switches.iter().find(|s| !(s.is_finite() && **s > 0.0)) {
            return Err(Error::Config(format!(
                "{model}: switch distance {bad} is not a positive number"
            )));
        }
        for w in switches.windows(2) {
            let (a, b) = (w[0], w[1]);
            let (b_lo, _) = self.band_of(b, false);
            let (_, a_hi) = self.band_of(a, true);
            if a >= b {
                return Err(Error::Config(format!(
                    "{model}: switch distances must increase, got {a} then {b}"
                )));
            }
            if self.fade == FadeMode::Distance && a_hi >= b_lo {
                return Err(Error::Config(format!(
                    "{model}: transition bands overlap between switch distances {a} and {b} \
                     (band {}, hysteresis {}); use a smaller --band or move the switches apart",
                    self.band, self.hysteresis
                )));
            }
        }
        Ok(())
    }

    /// The distance band of switch distance `s` when coarsening (`true`) or refining.
    fn band_of(&self, s: f32, coarsening: bool) -> (f32, f32) {
        let c = if coarsening {
            s * (1.0 + self.hysteresis)
        } else {
            s * (1.0 - self.hysteresis)
        };
        (c * (1.0 - self.band), c * (1.0 + self.band))
    }
}

/// What one instance shows on one frame. `lod_from == lod_to` means the instance is not in transition (k = 0).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct InstanceState {
    pub lod_from: u32,
    pub lod_to: u32,
    /// Progress of the transition from `lod_from` to `lod_to`, in [0, 1].
    pub k: f32,
}

impl InstanceState {
    pub fn steady(lod: u32) -> Self {
        InstanceState {
            lod_from: lod,
            lod_to: lod,
            k: 0.0,
        }
    }

    /// A t-instance in the papers' words: one that is between two LODs.
    pub fn in_transition(&self) -> bool {
        self.lod_from != self.lod_to
    }

    /// The blending methods' shadow caster: the instance's LOD, or both LODs dithered in a transition.
    pub fn blended_caster(&self) -> Caster {
        if self.in_transition() {
            Caster::Dither {
                from: self.lod_from,
                to: self.lod_to,
                k: self.k,
            }
        } else {
            Caster::Lod(self.lod_from)
        }
    }

    /// `--shadow-lod`'s choice for a method whose own (`follow`) caster is `own`.
    pub fn caster_under(&self, own: Caster, lod: ShadowLod) -> Caster {
        match (lod, self.in_transition()) {
            (ShadowLod::Follow, _) | (_, false) => own,
            (ShadowLod::LodFrom, true) => Caster::Lod(self.lod_from),
            (ShadowLod::LodTo, true) => Caster::Lod(self.lod_to),
        }
    }

    /// The continuous LOD value `lod_from + k (lod_to - lod_from)`, the same for every method.
    pub fn lod_value(&self) -> f32 {
        self.lod_from as f32 + self.k * (self.lod_to as f32 - self.lod_from as f32)
    }

    /// The LOD a hard switch at the band's centre shows.
    pub fn discrete_lod(&self) -> u32 {
        if self.k < 0.5 {
            self.lod_from
        } else {
            self.lod_to
        }
    }
}

#[derive(Debug, Clone, Copy)]
struct Track {
    /// The settled LOD (the one shown outside transitions).
    sel: u32,
    /// Time mode: the transition in progress (to, k).
    fading: Option<(u32, f32)>,
}

/// Per-instance schedule state. Feed it the frames in order, from frame 0.
#[derive(Debug, Clone)]
pub struct LodSchedule {
    params: ScheduleParams,
    tracks: Vec<Option<Track>>,
    /// Instances fading now, and of this frame's updates so far those held back by `--max-transitions`.
    slots: Slots,
}

#[derive(Debug, Clone, Copy, Default)]
struct Slots {
    fading: u32,
    waiting: u32,
}

impl LodSchedule {
    pub fn new(params: ScheduleParams, instances: usize) -> Self {
        LodSchedule {
            params,
            tracks: vec![None; instances],
            slots: Slots::default(),
        }
    }

    pub fn params(&self) -> &ScheduleParams {
        &self.params
    }

    /// Forgets all history: the next update is treated as the first frame.
    pub fn reset(&mut self) {
        self.tracks.iter_mut().for_each(|t| *t = None);
        self.slots = Slots::default();
    }

    /// How many instances `--max-transitions` held back (their LOD should change, no slot was free) in the
    /// updates since the last call: called once a frame, after its updates, it is that frame's count.
    pub fn take_waiting(&mut self) -> u32 {
        std::mem::take(&mut self.slots.waiting)
    }

    /// The state of instance `i` at camera distance `d`, given its model's switch distances (LOD j+1 is
    /// selected beyond `switches[j]`).
    pub fn update(&mut self, i: usize, d: f32, switches: &[f32]) -> InstanceState {
        let p = self.params;
        let track = self.tracks[i].get_or_insert_with(|| Track {
            sel: switches.iter().filter(|&&s| d > s).count() as u32,
            fading: None,
        });
        match p.fade {
            FadeMode::Distance => distance_state(&p, track, d, switches),
            FadeMode::Time => time_state(&p, track, d, switches, &mut self.slots),
        }
    }
}

fn distance_state(p: &ScheduleParams, t: &mut Track, d: f32, s: &[f32]) -> InstanceState {
    let n = s.len() as u32;
    loop {
        if t.sel < n && d >= p.band_of(s[t.sel as usize], true).1 {
            t.sel += 1;
        } else if t.sel > 0 && d <= p.band_of(s[t.sel as usize - 1], false).0 {
            t.sel -= 1;
        } else {
            break;
        }
    }
    if t.sel < n {
        let (lo, hi) = p.band_of(s[t.sel as usize], true);
        if d > lo && d < hi {
            return InstanceState {
                lod_from: t.sel,
                lod_to: t.sel + 1,
                k: (d - lo) / (hi - lo),
            };
        }
    }
    if t.sel > 0 {
        let (lo, hi) = p.band_of(s[t.sel as usize - 1], false);
        if d > lo && d < hi {
            return InstanceState {
                lod_from: t.sel - 1,
                lod_to: t.sel,
                k: (d - lo) / (hi - lo),
            };
        }
    }
    InstanceState::steady(t.sel)
}

fn time_state(
    p: &ScheduleParams,
    t: &mut Track,
    d: f32,
    s: &[f32],
    slots: &mut Slots,
) -> InstanceState {
    let h = p.hysteresis;
    let n = s.len() as u32;
    let mut target = t.sel;
    loop {
        if target < n && d > s[target as usize] * (1.0 + h) {
            target += 1;
        } else if target > 0 && d < s[target as usize - 1] * (1.0 - h) {
            target -= 1;
        } else {
            break;
        }
    }
    let step = 1.0 / p.fade_frames as f32;
    let fading = match t.fading {
        Some((to, k)) => Some((to, k + step)),
        None if target != t.sel && p.max_transitions > 0 && slots.fading >= p.max_transitions => {
            slots.waiting += 1;
            None
        }
        None if target != t.sel => {
            slots.fading += 1;
            let to = if target > t.sel { t.sel + 1 } else { t.sel - 1 };
            Some((to, step))
        }
        None => None,
    };
    match fading {
        Some((to, k)) if k < 1.0 - 1e-6 => {
            t.fading = Some((to, k));
            InstanceState {
                lod_from: t.sel,
                lod_to: to,
                k,
            }
        }
        Some((to, _)) => {
            t.sel = to;
            t.fading = None;
            slots.fading -= 1;
            InstanceState::steady(to)
        }
        None => InstanceState::steady(t.sel),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const S: [f32; 3] = [10.0, 20.0, 40.0];

    fn sweep(params: ScheduleParams, ds: &[f32]) -> Vec<InstanceState> {
        let mut s = LodSchedule::new(params, 1);
        ds.iter().map(|&d| s.update(0, d, &S)).collect()
    }

    fn ramp(a: f32, b: f32, n: usize) -> Vec<f32> {
        (0..n)
            .map(|i| a + (b - a) * i as f32 / (n - 1) as f32)
            .collect()
    }

    #[test]
    fn k_is_monotone_through_each_band_and_zero_outside() {
        let p = ScheduleParams::default();
        let ds = ramp(5.0, 50.0, 4001);
        let states = sweep(p, &ds);
        for (d, st) in ds.iter().zip(&states) {
            let in_band = S.iter().any(|s| *d > s * 0.95 && *d < s * 1.05);
            assert_eq!(st.in_transition(), in_band, "d={d} {st:?}");
            if !st.in_transition() {
                assert_eq!(st.k, 0.0);
            }
            assert!((0.0..=1.0).contains(&st.k));
        }
        for w in states.windows(2) {
            if w[0].in_transition() && w[1].in_transition() && w[0].lod_from == w[1].lod_from {
                assert!(w[1].k >= w[0].k, "{:?} -> {:?}", w[0], w[1]);
            }
        }
        // lod_value rises monotonically from 0 to 3 on the way out.
        for w in states.windows(2) {
            assert!(w[1].lod_value() >= w[0].lod_value());
        }
        assert_eq!(states[0].lod_value(), 0.0);
        assert_eq!(states.last().unwrap().lod_value(), 3.0);
        // The band's centre is the switch distance: k = 0.5 there.
        let mut s = LodSchedule::new(p, 1);
        let st = s.update(0, 20.0, &S);
        assert_eq!((st.lod_from, st.lod_to), (1, 2));
        assert!((st.k - 0.5).abs() < 1e-6);
    }

    #[test]
    fn same_states_out_and_back() {
        let p = ScheduleParams::default();
        let mut ds = ramp(5.0, 50.0, 901);
        let back: Vec<f32> = ds.iter().rev().copied().collect();
        let out = sweep(p, &ds);
        ds.extend(back);
        let both = sweep(p, &ds);
        let returned: Vec<_> = both[901..].iter().rev().copied().collect();
        assert_eq!(out, returned);
    }

    #[test]
    fn discrete_switches_at_band_centre() {
        let states = sweep(ScheduleParams::default(), &[9.9, 10.1, 19.9, 20.1]);
        let lods: Vec<u32> = states.iter().map(|s| s.discrete_lod()).collect();
        assert_eq!(lods, vec![0, 1, 1, 2]);
    }

    /// Jitter of +/- 3 % around a switch distance: the discrete LOD flip-flops without hysteresis, never with
    /// a 10 % margin.
    #[test]
    fn hysteresis_stops_flip_flopping_under_jitter() {
        let mut rng = crate::rng::SplitMix64::new(7);
        let ds: Vec<f32> = (0..1000)
            .map(|_| 20.0 * (1.0 + 0.03 * (2.0 * rng.next_f32() - 1.0)))
            .collect();
        let flips = |h: f32, fade: FadeMode| {
            let p = ScheduleParams {
                hysteresis: h,
                fade,
                fade_frames: 4,
                ..Default::default()
            };
            let st = sweep(p, &ds);
            st.windows(2)
                .filter(|w| w[0].discrete_lod() != w[1].discrete_lod())
                .count()
        };
        let without = flips(0.0, FadeMode::Distance);
        let with = flips(0.1, FadeMode::Distance);
        assert!(
            without > 100,
            "expected flip-flopping without hysteresis, got {without}"
        );
        assert_eq!(with, 0);
        let without_t = flips(0.0, FadeMode::Time);
        let with_t = flips(0.1, FadeMode::Time);
        assert!(without_t > 20, "time fade without hysteresis: {without_t}");
        assert_eq!(with_t, 0);
    }

    #[test]
    fn time_fade_advances_when_camera_stops() {
        let p = ScheduleParams {
            fade: FadeMode::Time,
            fade_frames: 5,
            ..Default::default()
        };
        // Cross the first switch, then stand still.
        let states = sweep(p, &[9.0, 11.0, 11.0, 11.0, 11.0, 11.0, 11.0]);
        assert_eq!(states[0], InstanceState::steady(0));
        let ks: Vec<f32> = states[1..5].iter().map(|s| s.k).collect();
        for (j, k) in ks.iter().enumerate() {
            assert!((k - (j + 1) as f32 / 5.0).abs() < 1e-5, "{ks:?}");
            assert_eq!((states[j + 1].lod_from, states[j + 1].lod_to), (0, 1));
        }
        assert_eq!(states[5], InstanceState::steady(1));
        assert_eq!(states[6], InstanceState::steady(1));
    }

    #[test]
    fn time_fade_goes_one_lod_at_a_time() {
        let p = ScheduleParams {
            fade: FadeMode::Time,
            fade_frames: 2,
            ..Default::default()
        };
        let states = sweep(p, &[5.0, 45.0, 45.0, 45.0, 45.0, 45.0, 45.0, 45.0]);
        let pairs: Vec<(u32, u32)> = states.iter().map(|s| (s.lod_from, s.lod_to)).collect();
        assert_eq!(
            pairs,
            vec![
                (0, 0),
                (0, 1),
                (1, 1),
                (1, 2),
                (2, 2),
                (2, 3),
                (3, 3),
                (3, 3)
            ]
        );
    }

    /// `--max-transitions 1`: three instances crossing their switch on the same frame fade one after another
    /// (never two at once), each waiting for the one before, where without the cap all three fade together.
    #[test]
    fn a_cap_on_transitions_queues_them() {
        let run = |cap: u32| {
            let p = ScheduleParams {
                fade: FadeMode::Time,
                fade_frames: 4,
                max_transitions: cap,
                ..Default::default()
            };
            p.validate().unwrap();
            let mut sch = LodSchedule::new(p, 3);
            let mut frames = Vec::new();
            for f in 0..16 {
                let d = if f == 0 { 5.0 } else { 15.0 };
                let states: Vec<InstanceState> = (0..3).map(|i| sch.update(i, d, &S)).collect();
                frames.push((states, sch.take_waiting()));
            }
            frames
        };
        let fading = |fr: &[(Vec<InstanceState>, u32)]| -> Vec<usize> {
            fr.iter()
                .map(|(s, _)| s.iter().filter(|s| s.in_transition()).count())
                .collect()
        };
        let (free, capped) = (run(0), run(1));
        assert_eq!(fading(&free)[..5], [0, 3, 3, 3, 0]);
        assert!(free.iter().all(|(_, w)| *w == 0));
        let n = fading(&capped);
        assert!(n.iter().all(|&n| n <= 1), "{n:?}");
        // Each fade shows k in (0, 1) on 3 frames and ends on the 4th, where the next instance (updated after it)
        // takes the freed slot at once.
        assert_eq!(n[..13], [0, 1, 1, 1, 1, 1, 1, 1, 1, 1, 0, 0, 0]);
        let waiting: Vec<u32> = capped.iter().map(|(_, w)| *w).collect();
        assert_eq!(waiting[..10], [0, 2, 2, 2, 1, 1, 1, 0, 0, 0]);
        assert!(capped[15].0.iter().all(|s| *s == InstanceState::steady(1)));
        let distance = ScheduleParams {
            max_transitions: 2,
            ..Default::default()
        };
        let e = distance.validate().unwrap_err().to_string();
        assert!(
            e.contains("--max-transitions 2") && e.contains("--fade time"),
            "{e}"
        );
    }

    #[test]
    fn overlapping_bands_are_rejected() {
        let p = ScheduleParams {
            band: 0.3,
            ..Default::default()
        };
        assert!(p.check_switches("m", &[10.0, 15.0]).is_err());
        assert!(ScheduleParams::default()
            .check_switches("m", &[10.0, 15.0])
            .is_ok());
        assert!(ScheduleParams::default()
            .check_switches("m", &[10.0, 9.0])
            .is_err());
        assert!(ScheduleParams::default()
            .check_switches("m", &[f32::NAN])
            .is_err());
    }

    #[test]
    fn policy_overrides_only_transitions() {
        let t = InstanceState {
            lod_from: 1,
            lod_to: 2,
            k: 0.3,
        };
        let own = t.blended_caster();
        assert_eq!(
            own,
            Caster::Dither {
                from: 1,
                to: 2,
                k: 0.3
            }
        );
        assert_eq!(t.caster_under(own, ShadowLod::LodTo), Caster::Lod(2));
        assert_eq!(t.caster_under(own, ShadowLod::LodFrom), Caster::Lod(1));
        assert_eq!(t.caster_under(own, ShadowLod::Follow), own);
        let steady = InstanceState::steady(3);
        assert_eq!(
            steady.caster_under(steady.blended_caster(), ShadowLod::LodTo),
            Caster::Lod(3)
        );
    }
}
