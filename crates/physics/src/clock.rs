//! A fixed-timestep clock: frames of any length become whole physics steps,
//! so the simulation does not depend on the frame rate.

/// Accumulates frame time and hands out fixed steps.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FixedStep {
    /// Seconds per step.
    pub step: f64,
    /// Most steps one frame may run: a slow frame (a build, a CPU
    /// rasteriser) slows the simulation down rather than stalling the next
    /// frame for ever longer catch-ups.
    pub max_steps: u32,
    carried: f64,
}

impl FixedStep {
    /// A clock of `step` seconds, at most `max_steps` a frame.
    pub fn new(step: f64, max_steps: u32) -> Self {
        FixedStep {
            step,
            max_steps,
            carried: 0.0,
        }
    }

    /// Add a frame of `dt` seconds: the steps to run now. Time beyond
    /// `max_steps` is dropped; a negative or non-finite `dt` adds nothing.
    pub fn advance(&mut self, dt: f64) -> u32 {
        if dt.is_finite() && dt > 0.0 {
            self.carried += dt;
        }
        let steps = (self.carried / self.step).floor();
        if steps >= f64::from(self.max_steps) {
            self.carried = 0.0;
            return self.max_steps;
        }
        self.carried -= steps * self.step;
        steps as u32
    }
}

#[cfg(test)]
mod tests {
    use super::FixedStep;

    #[test]
    fn frames_of_any_length_give_the_same_steps_per_second() {
        for frame in [1.0 / 144.0, 1.0 / 60.0, 1.0 / 25.0, 0.1] {
            let mut clock = FixedStep::new(1.0 / 60.0, 100);
            let frames = (2.0 / frame) as u32;
            let steps: u32 = (0..frames).map(|_| clock.advance(frame)).sum();
            assert!(
                (119..=121).contains(&steps),
                "{steps} steps in 2 s of {frame} s frames"
            );
        }
    }

    #[test]
    fn a_stall_runs_at_most_max_steps() {
        let mut clock = FixedStep::new(1.0 / 60.0, 8);
        assert_eq!(clock.advance(5.0), 8);
        assert_eq!(clock.advance(1.0 / 60.0 + 1e-9), 1);
        assert_eq!(clock.advance(f64::NAN), 0);
    }
}
