//! Wall-clock times of a run's stages, as the report lists them.

use std::time::Instant;

/// One timed stage.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Stage {
    /// Stage name.
    pub name: &'static str,
    /// Wall-clock seconds.
    pub seconds: f64,
}

/// A stopwatch over consecutive stages: each [`StageTimer::lap`] ends the current stage, which
/// began at the previous lap (or at [`StageTimer::new`]).
#[derive(Debug, Clone)]
pub struct StageTimer {
    stages: Vec<Stage>,
    last: Instant,
}

impl StageTimer {
    /// A timer whose first stage starts now.
    pub fn new() -> Self {
        StageTimer {
            stages: Vec::new(),
            last: Instant::now(),
        }
    }

    /// Ends the current stage as `name` and starts the next one; a stage run again (a count
    /// correction) adds to its time and keeps its first place in the list.
    pub fn lap(&mut self, name: &'static str) {
        let now = Instant::now();
        let seconds = (now - self.last).as_secs_f64();
        match self.stages.iter_mut().find(|s| s.name == name) {
            Some(s) => s.seconds += seconds,
            None => self.stages.push(Stage { name, seconds }),
        }
        self.last = now;
    }

    /// The stages so far, in the order they first ended; the timer starts an empty list.
    pub fn take_stages(&mut self) -> Vec<Stage> {
        std::mem::take(&mut self.stages)
    }
}

impl Default for StageTimer {
    fn default() -> Self {
        Self::new()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_stage_run_twice_adds_up_in_its_first_place() {
        let mut t = StageTimer::new();
        t.lap("a");
        std::thread::sleep(std::time::Duration::from_millis(5));
        t.lap("b");
        t.lap("a");
        let stages = t.take_stages();
        let names: Vec<_> = stages.iter().map(|s| s.name).collect();
        assert_eq!(names, ["a", "b"]);
        assert!(stages[1].seconds >= 0.005, "{stages:?}");
        assert!(stages.iter().all(|s| s.seconds >= 0.0));
        assert!(t.take_stages().is_empty());
    }
}
