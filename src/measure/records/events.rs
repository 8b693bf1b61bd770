//! Pop events: what a person sees of a run's transitions. Transitions of one block and method that start within
//! [`WAVE_GAP_FRAMES`] frames of the previous one's end are one event (a forest flight's switches come in waves,
//! and a wave is seen as one), scored by the combined change of its transitions: the root of the sum of their
//! squared lodpop_max, the lodpop of their changes had they fallen on one frame (exact where they cover
//! different pixels). An event is visible when its score exceeds a threshold: 1 JND of a calibration, else the
//! run's lodpop budget. summary.csv's `pop_events` and `visible_pops_per_min` count them.

use super::summaries::SummaryRecord;
use super::transitions::TransitionRecord;

/// Transitions that start at most this many frames after the last one's end join its event: 50 ms at 60 Hz.
pub const WAVE_GAP_FRAMES: u32 = 3;

/// One event: a run of transitions (in frame order) whose gaps are at most [`WAVE_GAP_FRAMES`].
#[derive(Debug, Clone, PartialEq)]
pub struct PopEvent {
    pub first_frame: u32,
    pub last_frame: u32,
    pub transitions: u32,
    /// sqrt(sum of lodpop_max^2) over its transitions.
    pub lodpop: f64,
}

/// The events of one block and method's transitions; None where a transition has no lodpop (`--quality off`).
pub fn pop_events(transitions: &[&TransitionRecord]) -> Option<Vec<PopEvent>> {
    let mut ts: Vec<&TransitionRecord> = transitions.to_vec();
    ts.sort_by_key(|t| t.first_frame);
    let mut events: Vec<(PopEvent, f64)> = Vec::new();
    for t in ts {
        let p = t.lodpop_max?;
        match events.last_mut() {
            Some((e, sum)) if t.first_frame <= e.last_frame + WAVE_GAP_FRAMES => {
                e.last_frame = e.last_frame.max(t.last_frame);
                e.transitions += 1;
                *sum += p * p;
            }
            _ => events.push((
                PopEvent {
                    first_frame: t.first_frame,
                    last_frame: t.last_frame,
                    transitions: 1,
                    lodpop: 0.0,
                },
                p * p,
            )),
        }
    }
    Some(
        events
            .into_iter()
            .map(|(e, sum)| PopEvent {
                lodpop: sum.sqrt(),
                ..e
            })
            .collect(),
    )
}

/// What counts as a visible pop, and how long a minute of the path is.
#[derive(Debug, Clone, Copy)]
pub struct Visibility {
    /// lodpop above which an event is visible (1 JND, or the budget); None: the block's default budget, half its
    /// hard switch's (`discrete`) largest lodpop, as the answer's.
    pub threshold: Option<f64>,
    /// The path's frame rate (frames a second).
    pub fps: f64,
    /// With a calibration: 1 JND in lodpop, for `lodpop_max_jnd`.
    pub jnd: Option<f64>,
}

/// Sets each summary's `pop_events`, `visible_pop_threshold`, `visible_pops_per_min` and `lodpop_max_jnd` from
/// the run's transitions, and each transition's `lodpop_max_jnd`.
pub fn set_visible_pops(
    summaries: &mut [SummaryRecord],
    transitions: &mut [TransitionRecord],
    v: Visibility,
) {
    for t in transitions.iter_mut() {
        t.lodpop_max_jnd = v.jnd.and_then(|j| Some(t.lodpop_max? / j));
    }
    let hard: Vec<((String, u32), Option<f64>)> = summaries
        .iter()
        .filter(|s| s.method == "discrete")
        .map(|s| ((s.scene.clone(), s.count), s.lodpop_max))
        .collect();
    for s in summaries.iter_mut() {
        let default = hard
            .iter()
            .find(|(k, _)| k.0 == s.scene && k.1 == s.count)
            .and_then(|(_, p)| p.map(|p| p / 2.0));
        let threshold = v.threshold.or(default).filter(|&t| t > 0.0);
        let mine: Vec<&TransitionRecord> = transitions
            .iter()
            .filter(|t| t.scene == s.scene && t.method == s.method && t.count == s.count)
            .collect();
        let events = pop_events(&mine);
        s.pop_events = events.as_ref().map(|e| e.len() as u32);
        s.visible_pop_threshold = threshold;
        let minutes = s.frames as f64 / v.fps / 60.0;
        s.visible_pops_per_min = match (&events, threshold) {
            (Some(e), Some(th)) if minutes > 0.0 => {
                Some(e.iter().filter(|e| e.lodpop > th).count() as f64 / minutes)
            }
            _ => None,
        };
        s.lodpop_max_jnd = v.jnd.and_then(|j| Some(s.lodpop_max? / j));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn transition(method: &str, first: u32, last: u32, lodpop: f64) -> TransitionRecord {
        TransitionRecord {
            scene: "trees".into(),
            method: method.into(),
            count: 1,
            transition: 0,
            first_frame: first,
            last_frame: last,
            lods: "0->1".into(),
            lodpop_max: Some(lodpop),
            lodpop_max_frame: Some(first),
            lodpop_coverage: None,
            lodpop_shading: None,
            pop_max: None,
            pop_max_frame: None,
            rmse_max: None,
            shadow_lodpop_max: None,
            lodpop_max_jnd: None,
        }
    }

    #[test]
    fn a_wave_of_switches_within_a_few_frames_is_one_event_scored_by_their_combined_change() {
        // A planted wave: 16 instances switching on frames 100 to 106, each 0.003 (under a 0.004 threshold
        // alone), then one lone switch of 0.003 at frame 200.
        let mut ts: Vec<TransitionRecord> = (0..16)
            .map(|i| transition("discrete", 100 + (i % 4) * 2, 100 + (i % 4) * 2, 0.003))
            .collect();
        ts.push(transition("discrete", 200, 200, 0.003));
        let refs: Vec<&TransitionRecord> = ts.iter().collect();
        let events = pop_events(&refs).unwrap();
        assert_eq!(events.len(), 2, "{events:?}");
        assert_eq!(
            (
                events[0].first_frame,
                events[0].last_frame,
                events[0].transitions
            ),
            (100, 106, 16)
        );
        assert!((events[0].lodpop - 0.012).abs() < 1e-12, "sqrt(16) x 0.003");
        assert!((events[1].lodpop - 0.003).abs() < 1e-12);
        // A gap of WAVE_GAP_FRAMES + 1 splits a wave.
        let apart = [
            transition("d", 10, 12, 0.01),
            transition("d", 12 + WAVE_GAP_FRAMES + 1, 20, 0.01),
        ];
        assert_eq!(
            pop_events(&apart.iter().collect::<Vec<_>>()).unwrap().len(),
            2
        );
        let near = [
            transition("d", 10, 12, 0.01),
            transition("d", 12 + WAVE_GAP_FRAMES, 20, 0.01),
        ];
        assert_eq!(
            pop_events(&near.iter().collect::<Vec<_>>()).unwrap().len(),
            1
        );

        // Per minute at 60 fps over 600 frames (10 s): the wave is visible (0.012 > 0.004), the lone switch not.
        let mut s = SummaryRecord {
            scene: "trees".into(),
            method: "discrete".into(),
            count: 1,
            frames: 600,
            lodpop_max: Some(0.003),
            ..Default::default()
        };
        let v = Visibility {
            threshold: Some(0.004),
            fps: 60.0,
            jnd: Some(0.002),
        };
        set_visible_pops(std::slice::from_mut(&mut s), &mut ts, v);
        assert_eq!(s.pop_events, Some(2));
        assert_eq!(s.visible_pops_per_min, Some(6.0));
        assert_eq!(s.lodpop_max_jnd, Some(1.5));
        assert_eq!(ts[0].lodpop_max_jnd, Some(1.5));
        // Without a threshold: half of discrete's largest lodpop (0.0015): both events are visible.
        set_visible_pops(
            std::slice::from_mut(&mut s),
            &mut ts,
            Visibility {
                threshold: None,
                jnd: None,
                ..v
            },
        );
        assert_eq!(
            (s.visible_pop_threshold, s.visible_pops_per_min),
            (Some(0.0015), Some(12.0))
        );
        assert_eq!(s.lodpop_max_jnd, None);
    }
}
