//! Wall-clock and processor times of a run's stages, as the report lists them.

use std::time::Instant;

use cpu_time::ProcessTime;

/// One timed stage.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Stage {
    /// Stage name.
    pub name: &'static str,
    /// Wall-clock seconds.
    pub seconds: f64,
    /// Processor seconds of the whole process (every thread, user and system) over the stage:
    /// `cpu_seconds / seconds` is how many cores it kept busy on average.
    pub cpu_seconds: f64,
}

/// A start point for one interval of wall-clock and processor time.
#[derive(Debug, Clone, Copy)]
pub struct Clock {
    wall: Instant,
    cpu: Option<ProcessTime>,
}

impl Clock {
    /// Starts now.
    pub fn start() -> Self {
        Clock {
            wall: Instant::now(),
            // The process clock (clock_gettime's CLOCK_PROCESS_CPUTIME_ID on Unix) exists on
            // every platform cpu-time supports; without it the processor time reads 0.
            cpu: ProcessTime::try_now().ok(),
        }
    }

    /// The wall-clock and processor seconds since the start.
    pub fn elapsed(&self) -> (f64, f64) {
        let cpu = self
            .cpu
            .and_then(|c| c.try_elapsed().ok())
            .map_or(0.0, |d| d.as_secs_f64());
        (self.wall.elapsed().as_secs_f64(), cpu)
    }
}

/// A stopwatch over consecutive stages: each [`StageTimer::lap`] ends the current stage, which
/// began at the previous lap (or at [`StageTimer::new`]).
#[derive(Debug, Clone)]
pub struct StageTimer {
    stages: Vec<Stage>,
    last: Clock,
}

impl StageTimer {
    /// A timer whose first stage starts now.
    pub fn new() -> Self {
        StageTimer {
            stages: Vec::new(),
            last: Clock::start(),
        }
    }

    /// Ends the current stage as `name` and starts the next one; a stage run again (a count
    /// correction) adds to its times and keeps its first place in the list.
    pub fn lap(&mut self, name: &'static str) {
        let next = Clock::start();
        let (seconds, cpu_seconds) = self.last.elapsed();
        add_stage(
            &mut self.stages,
            Stage {
                name,
                seconds,
                cpu_seconds,
            },
        );
        self.last = next;
    }

    /// The stages so far, in the order they first ended; the timer starts an empty list.
    pub fn take_stages(&mut self) -> Vec<Stage> {
        std::mem::take(&mut self.stages)
    }
}

/// Adds `stage` to `stages`: to the times of the stage of its name if there is one (which keeps
/// its place), else at the end.
pub fn add_stage(stages: &mut Vec<Stage>, stage: Stage) {
    match stages.iter_mut().find(|s| s.name == stage.name) {
        Some(s) => {
            s.seconds += stage.seconds;
            s.cpu_seconds += stage.cpu_seconds;
        }
        None => stages.push(stage),
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
        assert!(stages
            .iter()
            .all(|s| s.seconds >= 0.0 && s.cpu_seconds >= 0.0));
        assert!(t.take_stages().is_empty());
    }

    #[test]
    fn busy_work_takes_processor_time() {
        // Busy until the processor clock shows 20 ms (or 10 s pass on the wall clock): on a
        // loaded machine the wall clock runs ahead of the processor time, so the test asks only
        // that the processor clock moves with the work.
        let clock = Clock::start();
        let mut x = 0u64;
        while clock.elapsed().1 < 0.02 && clock.elapsed().0 < 10.0 {
            x = std::hint::black_box(x.wrapping_mul(6364136223846793005).wrapping_add(1));
        }
        let (wall, cpu) = clock.elapsed();
        assert!(cpu >= 0.02, "wall {wall}, cpu {cpu}");
    }
}
