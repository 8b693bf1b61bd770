//! Pop events: what a person sees of a run's LOD switches.
//!
//! A **switch** is one unit's run of consecutive frames on which its image changed: an instance whose state
//! draws differently from the frame before (`Counterfactual::same_image_state`: a discrete switch is one frame, a
//! blend every frame of it), or, in `lodbench score`, an object whose selection changed. Its **lodpop** is its
//! share of its frames' change: each frame's squared lodpop is split among the units that changed on it in
//! proportion to their weights (an instance's screen rectangle in pixels; equal in `score`), and a switch keeps
//! its largest share (frames where nothing changed, up to [`TRANSITION_TAIL`] after a switch, are shared among
//! the switches that ended there: TAA's and FSI's late changes).
//!
//! A **pop event** is a wave: the switches that begin within [`WAVE_WINDOW_S`] of the wave's first (a forest
//! flight's rows of trees switch in waves, and a wave is seen as one), scored by their combined change, the
//! root of the sum of their squared lodpop: the lodpop of their changes had they fallen on one frame (exact
//! where they cover different pixels, and for a wave whose switches all fall on one frame). A wave is anchored
//! at its first switch, so a path with a switch on every frame is a wave every [`WAVE_WINDOW_S`], not one event
//! for the path. An event is visible when its score exceeds a threshold: 1 JND of a calibration, else the run's
//! lodpop budget. events.csv lists them; summary.csv's `pop_events` and `visible_pops_per_min` count them.

use super::rows::FrameRecord;
use super::summaries::SummaryRecord;
use super::transitions::{TransitionRecord, TRANSITION_TAIL};
use serde::Serialize;
use std::collections::HashMap;

/// A switch that begins at most this long after a wave's first switch joins the wave: about the time over which
/// the eye sums a brief change (Bloch's law's critical duration, 50 to 100 ms), 6 frames at 60 fps.
pub const WAVE_WINDOW_S: f64 = 0.1;

/// [`WAVE_WINDOW_S`] in frames of a path at `fps` (rounded; 0 at 5 fps or less: every frame its own wave).
pub fn wave_window_frames(fps: f64) -> u32 {
    (WAVE_WINDOW_S * fps).round().max(0.0) as u32
}

/// The units that changed on one frame, each with its weight (its share of the frame's change goes by it).
pub type FrameChanges = Vec<(u32, f64)>;

/// One unit's switch (see the module's text).
#[derive(Debug, Clone, PartialEq)]
pub struct SwitchRecord {
    pub scene: String,
    pub method: String,
    pub count: u32,
    pub unit: u32,
    pub first_frame: u32,
    pub last_frame: u32,
    /// Its largest share of a frame's change, in lodpop (None where a frame has no lodpop: `--quality off`).
    pub lodpop: Option<f64>,
}

/// The switches of one block and method: `rows` its frames in order, `changes` per frame the units that changed.
pub fn switches(rows: &[FrameRecord], changes: &[FrameChanges]) -> Vec<SwitchRecord> {
    let mut out: Vec<SwitchRecord> = Vec::new();
    // Per switch: its largest squared share so far (None once a frame had no lodpop), and its last weight.
    let mut shares: Vec<(Option<f64>, f64)> = Vec::new();
    let mut open: HashMap<u32, usize> = HashMap::new();
    for (f, row) in rows.iter().enumerate() {
        let frame = row.frame;
        let now = changes.get(f).map(Vec::as_slice).unwrap_or_default();
        let mut here: Vec<(usize, f64)> = Vec::with_capacity(now.len());
        for &(unit, w) in now {
            let i = match open.get(&unit) {
                Some(&i) if out[i].last_frame + 1 == frame => i,
                _ => {
                    out.push(SwitchRecord {
                        scene: row.scene.clone(),
                        method: row.method.clone(),
                        count: row.count,
                        unit,
                        first_frame: frame,
                        last_frame: frame,
                        lodpop: None,
                    });
                    shares.push((Some(0.0), 0.0));
                    open.insert(unit, out.len() - 1);
                    out.len() - 1
                }
            };
            out[i].last_frame = frame;
            shares[i].1 = w;
            here.push((i, w));
        }
        if here.is_empty() {
            // A frame where nothing changed: its change (if any) is the late part of the switches ending just
            // before it.
            here = open
                .values()
                .filter(|&&i| {
                    out[i].last_frame < frame && frame <= out[i].last_frame + TRANSITION_TAIL
                })
                .map(|&i| (i, shares[i].1))
                .collect();
            here.sort_unstable_by_key(|h| h.0);
        }
        split_frame(row.lodpop, &here, &mut shares);
    }
    for (s, (share, _)) in out.iter_mut().zip(shares) {
        s.lodpop = share.map(f64::sqrt);
    }
    out
}

/// Shares one frame's squared `lodpop` among the switches `here` (index, weight) by weight (equally where every
/// weight is 0), keeping each switch's largest.
fn split_frame(lodpop: Option<f64>, here: &[(usize, f64)], shares: &mut [(Option<f64>, f64)]) {
    let total: f64 = here.iter().map(|h| h.1).sum();
    for &(i, w) in here {
        let part = if total > 0.0 {
            w / total
        } else {
            1.0 / here.len() as f64
        };
        shares[i].0 = match (shares[i].0, lodpop) {
            (Some(best), Some(l)) => Some(best.max(part * l * l)),
            _ => None,
        };
    }
}

/// One event: a wave of switches.
#[derive(Debug, Clone, PartialEq)]
pub struct PopEvent {
    pub first_frame: u32,
    pub last_frame: u32,
    pub switches: u32,
    /// sqrt(sum of the switches' lodpop^2).
    pub lodpop: f64,
}

/// The events of one block and method's switches, waves of `window` frames after their first; None where a
/// switch has no lodpop (`--quality off`).
pub fn pop_events(switches: &[&SwitchRecord], window: u32) -> Option<Vec<PopEvent>> {
    let mut ss: Vec<&SwitchRecord> = switches.to_vec();
    ss.sort_by_key(|s| (s.first_frame, s.unit));
    let mut events: Vec<(PopEvent, f64)> = Vec::new();
    for s in ss {
        let p = s.lodpop?;
        match events.last_mut() {
            Some((e, sum)) if s.first_frame <= e.first_frame + window => {
                e.last_frame = e.last_frame.max(s.last_frame);
                e.switches += 1;
                *sum += p * p;
            }
            _ => events.push((
                PopEvent {
                    first_frame: s.first_frame,
                    last_frame: s.last_frame,
                    switches: 1,
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

/// One row of events.csv: one pop event of one method on one scene block.
#[derive(Debug, Clone, Serialize, serde::Deserialize, PartialEq)]
pub struct EventRecord {
    pub scene: String,
    pub method: String,
    pub count: u32,
    /// 0-based index of the event along the path.
    pub event: u32,
    /// The first frame of its first switch and the last frame of its last.
    pub first_frame: u32,
    pub last_frame: u32,
    /// Switches in the wave.
    pub switches: u32,
    /// The wave's combined change, sqrt(sum of its switches' lodpop^2).
    pub lodpop: f64,
    /// With `--calibration`: lodpop in JNDs.
    pub lodpop_jnd: Option<f64>,
    /// Whether lodpop exceeds summary.csv's `visible_pop_threshold` (empty without one).
    pub visible: Option<bool>,
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
/// the run's switches, and each transition's `lodpop_max_jnd`; returns events.csv's rows.
pub fn set_visible_pops(
    summaries: &mut [SummaryRecord],
    transitions: &mut [TransitionRecord],
    switches: &[SwitchRecord],
    v: Visibility,
) -> Vec<EventRecord> {
    for t in transitions.iter_mut() {
        t.lodpop_max_jnd = v.jnd.and_then(|j| Some(t.lodpop_max? / j));
    }
    let hard: Vec<((String, u32), Option<f64>)> = summaries
        .iter()
        .filter(|s| s.method == "discrete")
        .map(|s| ((s.scene.clone(), s.count), s.lodpop_max))
        .collect();
    let mut rows = Vec::new();
    for s in summaries.iter_mut() {
        let default = hard
            .iter()
            .find(|(k, _)| k.0 == s.scene && k.1 == s.count)
            .and_then(|(_, p)| p.map(|p| p / 2.0));
        let threshold = v.threshold.or(default).filter(|&t| t > 0.0);
        let mine: Vec<&SwitchRecord> = switches
            .iter()
            .filter(|t| t.scene == s.scene && t.method == s.method && t.count == s.count)
            .collect();
        let events = s
            .lodpop_max
            .and_then(|_| pop_events(&mine, wave_window_frames(v.fps)));
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
        for (k, e) in events.into_iter().flatten().enumerate() {
            rows.push(EventRecord {
                scene: s.scene.clone(),
                method: s.method.clone(),
                count: s.count,
                event: k as u32,
                first_frame: e.first_frame,
                last_frame: e.last_frame,
                switches: e.switches,
                lodpop: e.lodpop,
                lodpop_jnd: v.jnd.map(|j| e.lodpop / j),
                visible: threshold.map(|th| e.lodpop > th),
            });
        }
    }
    rows
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::measure::records::tests::row;

    /// Frames 0..n with lodpop `lodpop(f)`.
    fn frames(n: u32, lodpop: impl Fn(u32) -> Option<f64>) -> Vec<FrameRecord> {
        (0..n)
            .map(|f| FrameRecord {
                lodpop: lodpop(f),
                ..row(f, None, 0.0, 0.0)
            })
            .collect()
    }

    /// Per frame of n, the units `changed(f)` lists, each of weight 1.
    fn changes(n: u32, changed: impl Fn(u32) -> Vec<u32>) -> Vec<FrameChanges> {
        (0..n)
            .map(|f| changed(f).into_iter().map(|u| (u, 1.0)).collect())
            .collect()
    }

    fn close(a: f64, b: f64) -> bool {
        (a - b).abs() < 1e-12
    }

    #[test]
    fn a_planted_wave_of_instance_switches_is_one_event_scored_by_their_combined_change() {
        // 16 instances switch (discrete: one frame each) 4 at a time on frames 100, 102, 104 and 106; alone each
        // changes the frame by 0.003 (under a 0.004 budget), so a frame of 4 has lodpop sqrt(4) x 0.003. Then one
        // lone switch of 0.003 at frame 200.
        let wave = |f: u32| (100..=106).contains(&f) && f.is_multiple_of(2);
        let rows = frames(240, |f| {
            Some(match f {
                _ if wave(f) => 0.006,
                200 => 0.003,
                _ => 0.0,
            })
        });
        let ch = changes(240, |f| match f {
            _ if wave(f) => (0..4).map(|i| (f - 100) / 2 * 4 + i).collect(),
            200 => vec![99],
            _ => vec![],
        });
        let sw = switches(&rows, &ch);
        assert_eq!(sw.len(), 17);
        assert!(sw.iter().all(|s| close(s.lodpop.unwrap(), 0.003)), "{sw:?}");
        let events = pop_events(&sw.iter().collect::<Vec<_>>(), wave_window_frames(60.0)).unwrap();
        assert_eq!(events.len(), 2, "{events:?}");
        assert_eq!(
            (
                events[0].first_frame,
                events[0].last_frame,
                events[0].switches
            ),
            (100, 106, 16)
        );
        assert!(close(events[0].lodpop, 0.012), "sqrt(16) x 0.003");
        assert!(close(events[1].lodpop, 0.003));
    }

    #[test]
    fn a_wave_is_anchored_at_its_first_switch_so_a_steady_stream_is_many_events() {
        assert_eq!(wave_window_frames(60.0), 6);
        assert_eq!(wave_window_frames(30.0), 3);
        // One instance after another, a switch every 2 frames for 64 frames: waves of 0, 2, 4, 6 (the window's
        // 6 frames after the first), then 8..14, and so on: 8 events, where chaining them would make one.
        let rows = frames(64, |_| Some(0.002));
        let ch = changes(64, |f| if f.is_multiple_of(2) { vec![f] } else { vec![] });
        let sw = switches(&rows, &ch);
        let events = pop_events(&sw.iter().collect::<Vec<_>>(), 6).unwrap();
        assert_eq!(events.len(), 8);
        assert!(events
            .iter()
            .all(|e| e.switches == 4 && close(e.lodpop, 0.004)));
        // The window's edge: 6 frames after the first joins, 7 does not.
        let edge = |gap: u32| {
            let rows = frames(20, |_| Some(0.001));
            let ch = changes(20, |f| match f {
                0 => vec![0],
                _ if f == gap => vec![1],
                _ => vec![],
            });
            let sw = switches(&rows, &ch);
            pop_events(&sw.iter().collect::<Vec<_>>(), 6).unwrap().len()
        };
        assert_eq!((edge(6), edge(7)), (1, 2));
    }

    #[test]
    fn overlapping_blends_share_each_frame_by_weight_and_keep_their_largest_share() {
        // Instance 0 blends over frames 10..=20, instance 1 (three times its pixels) over 15..=25; every frame
        // changes by 0.001.
        let rows = frames(40, |_| Some(0.001));
        let ch: Vec<FrameChanges> = (0..40u32)
            .map(|f| {
                let mut c = Vec::new();
                if (10..=20).contains(&f) {
                    c.push((0, 1.0));
                }
                if (15..=25).contains(&f) {
                    c.push((1, 3.0));
                }
                c
            })
            .collect();
        let sw = switches(&rows, &ch);
        assert_eq!(sw.len(), 2);
        assert_eq!((sw[0].first_frame, sw[0].last_frame), (10, 20));
        assert_eq!((sw[1].first_frame, sw[1].last_frame), (15, 25));
        // Each has frames of its own, where the whole change is its.
        assert!(close(sw[0].lodpop.unwrap(), 0.001) && close(sw[1].lodpop.unwrap(), 0.001));
        // Only shared frames: a quarter and three quarters of the squared change.
        let shared = switches(
            &rows,
            &changes(40, |f| {
                if (15..=20).contains(&f) {
                    vec![0, 1]
                } else {
                    vec![]
                }
            }),
        );
        assert!(close(shared[0].lodpop.unwrap(), 0.001 * 0.5_f64.sqrt()));
        let weighted: Vec<FrameChanges> = (0..40u32)
            .map(|f| {
                if (15..=20).contains(&f) {
                    vec![(0, 1.0), (1, 3.0)]
                } else {
                    vec![]
                }
            })
            .collect();
        let w = switches(&rows, &weighted);
        assert!(close(w[0].lodpop.unwrap(), 0.001 * 0.25_f64.sqrt()));
        assert!(close(w[1].lodpop.unwrap(), 0.001 * 0.75_f64.sqrt()));
        // A unit changing again after a pause is a new switch.
        let again = switches(
            &rows,
            &changes(40, |f| if f == 3 || f == 9 { vec![7] } else { vec![] }),
        );
        assert_eq!(again.len(), 2);
    }

    #[test]
    fn a_late_change_after_a_switch_is_its_own_within_the_tail_and_quality_off_has_no_events() {
        // A switch on frame 10 whose change shows on frame 11 (a lag, TAA's history), and a change on frame 20,
        // more than TRANSITION_TAIL frames after any switch: no switch's.
        let rows = frames(30, |f| {
            Some(match f {
                11 => 0.005,
                20 => 0.009,
                _ => 0.0,
            })
        });
        let sw = switches(
            &rows,
            &changes(30, |f| if f == 10 { vec![0] } else { vec![] }),
        );
        assert_eq!(sw.len(), 1);
        assert!(close(sw[0].lodpop.unwrap(), 0.005));
        // --quality off: no lodpop, no events.
        let off = switches(
            &frames(30, |_| None),
            &changes(30, |f| if f == 10 { vec![0] } else { vec![] }),
        );
        assert_eq!(off[0].lodpop, None);
        assert_eq!(pop_events(&off.iter().collect::<Vec<_>>(), 6), None);
        // No switch at all: no events, not none.
        assert_eq!(pop_events(&[], 6), Some(vec![]));
    }

    fn switch(first: u32, unit: u32, lodpop: f64) -> SwitchRecord {
        SwitchRecord {
            scene: "trees".into(),
            method: "discrete".into(),
            count: 1,
            unit,
            first_frame: first,
            last_frame: first,
            lodpop: Some(lodpop),
        }
    }

    #[test]
    fn visible_pops_per_minute_count_the_events_over_the_threshold() {
        // A wave of 16 switches of 0.003 on frames 100..=106 and a lone one at frame 200, over 600 frames (10 s)
        // at 60 fps: the wave is visible over 0.004 (0.012), the lone switch not.
        let mut sw: Vec<SwitchRecord> = (0..16)
            .map(|i| switch(100 + (i % 4) * 2, i, 0.003))
            .collect();
        sw.push(switch(200, 99, 0.003));
        let mut s = SummaryRecord {
            scene: "trees".into(),
            method: "discrete".into(),
            count: 1,
            frames: 600,
            lodpop_max: Some(0.006),
            ..Default::default()
        };
        let v = Visibility {
            threshold: Some(0.004),
            fps: 60.0,
            jnd: Some(0.002),
        };
        let rows = set_visible_pops(std::slice::from_mut(&mut s), &mut [], &sw, v);
        assert_eq!(s.pop_events, Some(2));
        assert_eq!(s.visible_pops_per_min, Some(6.0));
        assert_eq!(s.lodpop_max_jnd, Some(3.0));
        assert_eq!(rows.len(), 2);
        assert_eq!(
            (rows[0].switches, rows[0].visible, rows[1].visible),
            (16, Some(true), Some(false))
        );
        assert!(close(rows[0].lodpop_jnd.unwrap(), 6.0));
        // Without a threshold: half of discrete's largest lodpop (0.003): both events are visible.
        set_visible_pops(
            std::slice::from_mut(&mut s),
            &mut [],
            &sw,
            Visibility {
                threshold: None,
                jnd: None,
                ..v
            },
        );
        assert_eq!(
            (s.visible_pop_threshold, s.visible_pops_per_min),
            (Some(0.003), Some(6.0))
        );
        // Half of 0.006 is 0.003: the lone switch's 0.003 is not over it. A block without lodpop has no events.
        s.lodpop_max = None;
        set_visible_pops(std::slice::from_mut(&mut s), &mut [], &sw, v);
        assert_eq!((s.pop_events, s.visible_pops_per_min), (None, None));
    }
}
