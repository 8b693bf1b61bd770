//! Transition detection: which LODs a frame's instances in transition go between ([`TransitionPair`]), the
//! frames near a transition (`--dump-transitions`) and a row per transition (transitions.csv).

use super::rows::FrameRecord;
use serde::Serialize;

/// Which LODs the instances in transition on one frame go between.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum TransitionPair {
    /// No instance in transition.
    #[default]
    None,
    /// Every t-instance goes from the first LOD to the second.
    One(u32, u32),
    /// t-instances between different pairs of LODs.
    Mixed,
}

impl TransitionPair {
    /// The pair of a frame whose t-instances include one going `from` -> `to`.
    pub fn with(self, from: u32, to: u32) -> TransitionPair {
        match self {
            TransitionPair::None => TransitionPair::One(from, to),
            TransitionPair::One(a, b) if (a, b) == (from, to) => self,
            _ => TransitionPair::Mixed,
        }
    }

    /// The pair of a run of frames: this one's joined with a later frame's.
    pub fn join(self, other: TransitionPair) -> TransitionPair {
        match other {
            TransitionPair::None => self,
            TransitionPair::One(a, b) => self.with(a, b),
            TransitionPair::Mixed => TransitionPair::Mixed,
        }
    }

    fn text(self) -> String {
        match self {
            TransitionPair::None => String::new(),
            TransitionPair::One(a, b) => format!("{a}->{b}"),
            TransitionPair::Mixed => "mixed".into(),
        }
    }
}

/// Frames after a transition's last frame that still count as its own in transitions.csv: the frame after it
/// shows the end state (a schedule change, so lodpop's) and, for FSI, the frame after that still combines a
/// buffer from inside the transition.
pub const TRANSITION_TAIL: u32 = 2;

/// Frames before a transition's first frame that `--dump-transitions` dumps too, so a clip of the transition
/// (`lodbench perceptual`) starts from the picture before it.
pub const TRANSITION_LEAD: u32 = 2;

/// Per frame: whether it lies within [`TRANSITION_LEAD`] frames before or [`TRANSITION_TAIL`] frames after a
/// frame with an instance in transition (the frames `--dump-transitions` dumps).
pub fn near_transitions(t_instances: &[u32]) -> Vec<bool> {
    let n = t_instances.len();
    let mut near = vec![false; n];
    for (f, _) in t_instances.iter().enumerate().filter(|(_, &t)| t > 0) {
        let lo = f.saturating_sub(TRANSITION_LEAD as usize);
        let hi = (f + TRANSITION_TAIL as usize).min(n.saturating_sub(1));
        near[lo..=hi].fill(true);
    }
    near
}

/// One row of transitions.csv: one transition of the path (a maximal run of frames with an instance in
/// transition) for one method on one scene block, with its largest figures over the transition's frames and
/// the [`TRANSITION_TAIL`] frames after it.
#[derive(Debug, Clone, Serialize, serde::Deserialize, PartialEq)]
pub struct TransitionRecord {
    pub scene: String,
    pub method: String,
    pub count: u32,
    /// 0-based index of the transition along the path.
    pub transition: u32,
    /// First and last frame with an instance in transition.
    pub first_frame: u32,
    pub last_frame: u32,
    /// `lod_from->lod_to` of the t-instances (of the first frame's), or `mixed`.
    pub lods: String,
    /// The largest lodpop, pop and rmse over the transition's frames and the frame of each (empty, as the
    /// frame, with `--quality off`).
    pub lodpop_max: Option<f64>,
    pub lodpop_max_frame: Option<u32>,
    /// lodpop_max's parts on its frame: coverage^2 + shading^2 = lodpop_max^2 (FrameRecord::lodpop_coverage).
    #[serde(default)]
    pub lodpop_coverage: Option<f64>,
    #[serde(default)]
    pub lodpop_shading: Option<f64>,
    pub pop_max: Option<f64>,
    pub pop_max_frame: Option<u32>,
    pub rmse_max: Option<f64>,
    /// `--shadows on`: the largest shadow_lodpop over the same frames (empty without shadows).
    #[serde(default)]
    pub shadow_lodpop_max: Option<f64>,
    /// With `--calibration`: lodpop_max in JNDs of the calibration's lodpop threshold.
    #[serde(default)]
    pub lodpop_max_jnd: Option<f64>,
}

/// The transitions of one block: `rows` its frame records in frame order, `pairs` each frame's pair.
pub fn transitions(rows: &[FrameRecord], pairs: &[TransitionPair]) -> Vec<TransitionRecord> {
    let mut out = Vec::new();
    let mut f = 0;
    while f < rows.len() {
        if rows[f].t_instances == 0 {
            f += 1;
            continue;
        }
        let first = f;
        while f < rows.len() && rows[f].t_instances > 0 {
            f += 1;
        }
        let last = f - 1;
        let window = &rows[first..(last + 1 + TRANSITION_TAIL as usize).min(rows.len())];
        // The largest value over the window and its frame; None when a frame has no value.
        let argmax = |value: fn(&FrameRecord) -> Option<f64>| {
            window
                .iter()
                .try_fold((0.0f64, window[0].frame), |(best, at), r| {
                    let v = value(r)?;
                    Some(if v > best { (v, r.frame) } else { (best, at) })
                })
                .unzip()
        };
        let (lodpop_max, lodpop_max_frame) = argmax(|r| r.lodpop);
        let at_max = lodpop_max_frame.and_then(|f| window.iter().find(|r| r.frame == f));
        let (pop_max, pop_max_frame) = argmax(|r| r.pop);
        let r0 = &rows[first];
        out.push(TransitionRecord {
            scene: r0.scene.clone(),
            method: r0.method.clone(),
            count: r0.count,
            transition: out.len() as u32,
            first_frame: r0.frame,
            last_frame: rows[last].frame,
            // Over every frame of the transition: instances that start their transitions while others are
            // still in theirs make one run of frames.
            lods: pairs
                .get(first..=last)
                .unwrap_or_default()
                .iter()
                .fold(TransitionPair::None, |acc, &p| acc.join(p))
                .text(),
            lodpop_max,
            lodpop_max_frame,
            lodpop_coverage: at_max.and_then(|r| r.lodpop_coverage),
            lodpop_shading: at_max.and_then(|r| r.lodpop_shading),
            pop_max,
            pop_max_frame,
            rmse_max: argmax(|r| r.rmse).0,
            shadow_lodpop_max: window
                .iter()
                .map(|r| r.shadow_lodpop)
                .collect::<Option<Vec<f64>>>()
                .map(|v| v.into_iter().fold(0.0, f64::max)),
            lodpop_max_jnd: None,
        });
    }
    out
}
