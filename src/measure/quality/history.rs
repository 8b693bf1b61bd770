//! lodpop's history: the schedule states of the last frames, and whether this frame can differ from its
//! counterfactual.

use crate::scene::schedule::InstanceState;
use std::collections::VecDeque;

/// The schedule states of the last frames, newest first: lodpop's history.
pub(super) struct StateHistory {
    /// How many earlier frames the method's counterfactual reads (`Counterfactual::lodpop_history`, at least 1).
    pub(super) depth: usize,
    pub(super) frames: VecDeque<Vec<InstanceState>>,
}

impl StateHistory {
    pub(super) fn new(depth: usize) -> StateHistory {
        StateHistory {
            depth,
            frames: VecDeque::with_capacity(depth + 1),
        }
    }

    /// The previous frame's states (before [`StateHistory::push`] of this frame's).
    pub(super) fn previous(&self) -> Option<&[InstanceState]> {
        self.frames.front().map(Vec::as_slice)
    }

    pub(super) fn push(&mut self, states: &[InstanceState]) {
        self.frames.push_front(states.to_vec());
        self.frames.truncate(self.depth + 1);
    }

    /// Whether the frame after `push` can differ from its counterfactual: the states changed within the
    /// history (an instance's state is not `same` as before), a transition is under way with a history
    /// deeper than one frame, or the method says its selection changed (asked last).
    pub(super) fn changed(
        &self,
        same: impl Fn(&InstanceState, &InstanceState) -> bool,
        selection_changed: impl FnOnce() -> bool,
    ) -> bool {
        let h = &self.frames;
        let same_frame = |a: &[InstanceState], b: &[InstanceState]| {
            a.len() == b.len() && a.iter().zip(b).all(|(x, y)| same(x, y))
        };
        h.len() > 1
            && (h.iter().skip(1).any(|s| !same_frame(s, &h[0]))
                || (self.depth > 1 && h.iter().flatten().any(|s| s.in_transition()))
                || selection_changed())
    }

    /// The instances whose state this frame (after `push`) is not `same` as in an earlier frame of the history,
    /// or, with a history deeper than one frame, is in transition in any (the per-instance [`Self::changed`]).
    pub(super) fn changed_instances(
        &self,
        same: impl Fn(&InstanceState, &InstanceState) -> bool,
    ) -> Vec<usize> {
        let h = &self.frames;
        let Some(now) = h.front().filter(|_| h.len() > 1) else {
            return Vec::new();
        };
        let deep = self.depth > 1;
        (0..now.len())
            .filter(|&i| {
                h.iter()
                    .skip(1)
                    .any(|e| e.get(i).is_none_or(|b| !same(b, &now[i])))
                    || (deep
                        && h.iter()
                            .any(|e| e.get(i).is_some_and(|s| s.in_transition())))
            })
            .collect()
    }

    /// The earlier frames' states, newest first.
    pub(super) fn earlier(&self) -> Vec<&[InstanceState]> {
        self.frames.iter().skip(1).map(Vec::as_slice).collect()
    }

    /// Every frame's states kept, this frame's first.
    pub(super) fn all(&self) -> Vec<&[InstanceState]> {
        self.frames.iter().map(Vec::as_slice).collect()
    }
}

/// Whether two states of an instance draw the same image of it (`Counterfactual::same_image_state`).
pub(super) type SameImage<'m> = dyn Fn(&InstanceState, &InstanceState) -> bool + 'm;

#[cfg(test)]
mod tests {
    use super::*;

    fn states(lods: &[(u32, u32, f32)]) -> Vec<InstanceState> {
        lods.iter()
            .map(|&(lod_from, lod_to, k)| InstanceState {
                lod_from,
                lod_to,
                k,
            })
            .collect()
    }

    #[test]
    fn the_counterfactual_is_drawn_only_when_the_frame_can_differ() {
        let steady = states(&[(1, 1, 0.0), (2, 2, 0.0)]);
        let switched = states(&[(1, 1, 0.0), (3, 3, 0.0)]);
        let mut h = StateHistory::new(1);
        h.push(&steady);
        assert!(
            !h.changed(|a, b| a == b, || true),
            "the first frame has no earlier frame"
        );
        assert_eq!(h.previous(), Some(steady.as_slice()));
        h.push(&steady);
        assert!(!h.changed(|a, b| a == b, || false), "the same states twice");
        assert!(
            h.changed(|a, b| a == b, || true),
            "the method's own selection changed"
        );
        h.push(&switched);
        assert!(h.changed(|a, b| a == b, || false), "an instance switched");
        assert_eq!(
            h.earlier(),
            vec![steady.as_slice()],
            "depth 1 keeps one earlier frame"
        );
    }

    #[test]
    fn the_changed_instances_are_those_whose_state_is_not_the_same() {
        let before = states(&[(1, 1, 0.0), (2, 3, 0.4), (3, 3, 0.0)]);
        let now = states(&[(1, 1, 0.0), (2, 3, 0.6), (4, 4, 0.0)]);
        let mut h = StateHistory::new(1);
        h.push(&before);
        assert!(
            h.changed_instances(|a, b| a == b).is_empty(),
            "no earlier frame"
        );
        h.push(&now);
        assert_eq!(h.changed_instances(|a, b| a == b), vec![1, 2]);
        // A method that draws one LOD whatever k is (discrete): the blend's k moved, its image did not.
        let lod = |s: &InstanceState| if s.k < 0.5 { s.lod_from } else { s.lod_to };
        assert_eq!(h.changed_instances(|a, b| lod(a) == lod(b)), vec![1, 2]);
        let mut still = StateHistory::new(1);
        still.push(&before);
        still.push(&states(&[(1, 1, 0.0), (2, 3, 0.45), (3, 3, 0.0)]));
        assert!(still.changed_instances(|a, b| lod(a) == lod(b)).is_empty());
        // Two frames back, an instance in transition in any of them counts (FSI's older buffer).
        let mut deep = StateHistory::new(2);
        for s in [&before, &before, &before] {
            deep.push(s);
        }
        assert_eq!(deep.changed_instances(|a, b| a == b), vec![1]);
    }

    #[test]
    fn a_deeper_history_counts_a_transition_under_way() {
        let blending = states(&[(1, 2, 0.5)]);
        let mut shallow = StateHistory::new(1);
        let mut deep = StateHistory::new(2);
        for _ in 0..3 {
            shallow.push(&blending);
            deep.push(&blending);
        }
        assert!(
            !shallow.changed(|a, b| a == b, || false),
            "one frame back, the same blend state"
        );
        assert!(
            deep.changed(|a, b| a == b, || false),
            "two frames back, a transition under way"
        );
        assert_eq!(deep.earlier().len(), 2);
    }
}
