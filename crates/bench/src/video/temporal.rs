//! The temporal metric: how much a method's depth flickers between
//! consecutive frames beyond what the CPU reference's own frames do.
//!
//! The camera moves, so a pixel's distance changes from frame to frame in
//! any correct renderer; the reference says by how much. A pixel flickers
//! when the method's change departs from the reference's by more than the
//! coherence metric's tolerance (4 % of the distance, at least 0.04 units),
//! or when it switches between terrain and sky while the reference does not
//! (or the other way round). Scatterer speckle, sliding slice bands, LOD
//! pops and a voxel build catching up after an edit all count; a steady
//! error that stays put from frame to frame does not.

use serde::{Deserialize, Serialize};

/// Relative tolerance, as in the coherence metric (DESIGN §3).
pub const TOLERANCE: f32 = 0.04;

/// Does the pixel flicker between frames `a` and `b`? Distances; infinite = sky.
pub fn flickers(method: (f32, f32), reference: (f32, f32)) -> bool {
    let m_switch = method.0.is_finite() != method.1.is_finite();
    let r_switch = reference.0.is_finite() != reference.1.is_finite();
    if m_switch || r_switch {
        return m_switch != r_switch;
    }
    if !(method.0.is_finite() && reference.0.is_finite()) {
        // Sky in both frames for one of them: no depth change to compare.
        return false;
    }
    let dm = method.1 - method.0;
    let dr = reference.1 - reference.0;
    (dm - dr).abs() > TOLERANCE * reference.1.max(1.0)
}

/// Percent of pixels that flicker between two consecutive frames.
pub fn flicker_percent(method: (&[f32], &[f32]), reference: (&[f32], &[f32])) -> f64 {
    let n = method
        .0
        .len()
        .min(method.1.len())
        .min(reference.0.len())
        .min(reference.1.len());
    if n == 0 {
        return 0.0;
    }
    let count = (0..n)
        .filter(|&i| flickers((method.0[i], method.1[i]), (reference.0[i], reference.1[i])))
        .count();
    100.0 * count as f64 / n as f64
}

/// One method's flicker over a run of frames.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Flicker {
    /// Mean over consecutive frame pairs, percent of pixels.
    pub mean_percent: f64,
    /// The worst pair.
    pub max_percent: f64,
    /// Frame (the later of its pair) where the worst pair ends.
    pub max_at_frame: u32,
    pub pairs: u32,
}

/// Accumulates [`flicker_percent`] per frame pair.
#[derive(Clone, Debug, Default)]
pub struct FlickerTracker {
    sum: f64,
    worst: (f64, u32),
    pairs: u32,
}

impl FlickerTracker {
    pub fn add(&mut self, frame: u32, percent: f64) {
        self.sum += percent;
        self.pairs += 1;
        if percent > self.worst.0 || self.pairs == 1 {
            self.worst = (percent, frame);
        }
    }

    pub fn result(&self) -> Flicker {
        Flicker {
            mean_percent: if self.pairs == 0 {
                0.0
            } else {
                self.sum / f64::from(self.pairs)
            },
            max_percent: self.worst.0,
            max_at_frame: self.worst.1,
            pairs: self.pairs,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const SKY: f32 = f32::INFINITY;

    #[test]
    fn following_the_reference_is_not_flicker() {
        // The reference and the method both move 5 units nearer: no flicker,
        // even with a steady 2-unit error.
        assert!(!flickers((102.0, 97.0), (100.0, 95.0)));
        // The method jumps 10 units the reference does not.
        assert!(flickers((100.0, 110.0), (100.0, 100.0)));
        // Within 4 % of the distance is tolerated.
        assert!(!flickers((100.0, 103.0), (100.0, 100.0)));
        // Sky/terrain switches only count when the reference disagrees.
        assert!(flickers((SKY, 50.0), (50.0, 50.0)));
        assert!(!flickers((SKY, 50.0), (SKY, 50.0)));
        assert!(flickers((50.0, 50.0), (SKY, 50.0)));
        assert!(!flickers((SKY, SKY), (SKY, SKY)));
    }

    #[test]
    fn percent_over_the_image() {
        let r0 = [10.0, 10.0, SKY, 20.0];
        let r1 = [11.0, 10.0, SKY, 20.0];
        let m0 = [10.0, 10.0, SKY, 20.0];
        let m1 = [11.0, 30.0, 5.0, 20.0];
        assert_eq!(flicker_percent((&m0, &m1), (&r0, &r1)), 50.0);
        assert_eq!(flicker_percent((&r0, &r1), (&r0, &r1)), 0.0);
        assert_eq!(flicker_percent((&[], &[]), (&[], &[])), 0.0);
    }

    #[test]
    fn tracker_keeps_mean_and_worst() {
        let mut t = FlickerTracker::default();
        for (f, p) in [(1, 1.0), (2, 5.0), (3, 0.0)] {
            t.add(f, p);
        }
        let r = t.result();
        assert_eq!(
            (r.mean_percent, r.max_percent, r.max_at_frame, r.pairs),
            (2.0, 5.0, 2, 3)
        );
    }
}
