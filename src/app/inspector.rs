//! The picked shading point and where the stepper stands in its recorded stages: the step
//! shown, the group opened, the player. The panes draw from it (`ui/`); everything they show
//! comes from the [`Probe`] (the renderer's own recording), so a loaded debug dump replays
//! without the scene.

use crate::inspect::Probe;
use crate::views::stages::{Step, StepGroup, StepKind, probe_groups, probe_steps};

/// The picked point and where the stepper stands.
pub struct Inspector {
    pub probe: Probe,
    pub steps: Vec<Step>,
    /// The steps as the stepper lists them: a mesh taken face by face is one group.
    pub groups: Vec<StepGroup>,
    /// The group opened to step through its members one by one.
    pub open_group: Option<usize>,
    /// Index into `steps`; `None` shows every stage at once.
    pub step: Option<usize>,
    pub playing: bool,
    /// Seconds since the last automatic step.
    pub play_clock: f64,
}

impl Inspector {
    pub fn new(probe: Probe) -> Self {
        let steps = probe_steps(&probe);
        let groups = probe_groups(&probe, &steps);
        Inspector {
            probe,
            steps,
            groups,
            open_group: None,
            step: None,
            playing: false,
            play_clock: 0.0,
        }
    }

    pub fn current(&self) -> Option<&Step> {
        self.step.and_then(|i| self.steps.get(i))
    }

    /// The group of step `i`.
    pub(crate) fn group_of(&self, i: usize) -> Option<usize> {
        self.groups.iter().position(|g| g.contains(i))
    }

    /// Where stepping into group `g` lands: its first step when it is open, else the step it
    /// stands at (its last).
    fn entry(&self, g: usize, forwards: bool) -> usize {
        let group = &self.groups[g];
        if self.open_group == Some(g) && forwards {
            group.first
        } else {
            group.last()
        }
    }

    /// The next stage: the next step inside an open group, else the next group.
    pub fn next(&mut self) {
        if self.groups.is_empty() {
            return;
        }
        self.step = Some(match self.step {
            None => self.entry(0, true),
            Some(i) => match self.group_of(i) {
                Some(g) if self.open_group == Some(g) && i < self.groups[g].last() => i + 1,
                Some(g) if g + 1 < self.groups.len() => self.entry(g + 1, true),
                _ => i,
            },
        });
    }

    /// The previous stage: the previous step inside an open group, else the previous group.
    pub fn previous(&mut self) {
        self.step = match self.step.and_then(|i| Some((i, self.group_of(i)?))) {
            Some((i, g)) if self.open_group == Some(g) && i > self.groups[g].first => Some(i - 1),
            Some((_, g)) if g > 0 => Some(self.entry(g - 1, false)),
            _ => None,
        };
    }

    /// Advances the player by `dt` seconds (one step per 0.8 s); stops at the end.
    pub(crate) fn tick(&mut self, dt: f64) -> bool {
        if !self.playing {
            return false;
        }
        self.play_clock += dt;
        if self.play_clock < 0.8 {
            return false;
        }
        self.play_clock = 0.0;
        let at_end = self.step.is_some_and(|i| i + 1 >= self.steps.len());
        if at_end {
            self.playing = false;
        } else {
            self.next();
        }
        true
    }

    /// Whether the current step is a set difference (the planar view is then the one to see).
    pub(crate) fn at_set_difference(&self) -> bool {
        matches!(
            self.current().map(|s| s.kind),
            Some(StepKind::SetDifference { .. })
        )
    }
}
