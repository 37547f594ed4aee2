//! Per-pass GPU timestamps. The frame hands each pass a pair of query slots
//! through [`PassTimer`]; after the frame the pairs are resolved, read back and
//! summed. (Encoder-level stamps did not bracket multipass work reliably on
//! Metal — the paper's finding — so every pass is stamped on its own.)

use serde::Serialize;
use std::cell::RefCell;

/// Most timed passes per frame; later passes run untimed (and are reported).
pub const MAX_TIMED_PASSES: u32 = 32;

/// What one frame cost.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct FrameTimings {
    /// Sum of the per-pass GPU intervals, ms; `None` without timestamp support.
    pub gpu_ms: Option<f64>,
    /// CPU time from submit until the GPU finished, ms.
    pub cpu_ms: f64,
    /// CPU time to prepare and record the frame (before submit), ms.
    pub record_ms: f64,
    /// Each timed pass: label and GPU ms.
    pub passes: Vec<(String, f64)>,
    /// Passes beyond [`MAX_TIMED_PASSES`] that ran untimed.
    pub untimed_passes: u32,
}

/// Hands out timestamp slots to the passes of one frame.
pub struct PassTimer {
    query_set: Option<wgpu::QuerySet>,
    labels: RefCell<Vec<String>>,
    untimed: RefCell<u32>,
}

impl PassTimer {
    pub(crate) fn new(device: &wgpu::Device, enabled: bool) -> Self {
        let query_set = enabled.then(|| {
            device.create_query_set(&wgpu::QuerySetDescriptor {
                label: Some("pass timestamps"),
                ty: wgpu::QueryType::Timestamp,
                count: 2 * MAX_TIMED_PASSES,
            })
        });
        PassTimer {
            query_set,
            labels: RefCell::new(Vec::new()),
            untimed: RefCell::new(0),
        }
    }

    pub(crate) fn reset(&self) {
        self.labels.borrow_mut().clear();
        *self.untimed.borrow_mut() = 0;
    }

    fn next_slot(&self, label: &str) -> Option<(&wgpu::QuerySet, u32)> {
        let qs = self.query_set.as_ref()?;
        let mut labels = self.labels.borrow_mut();
        if labels.len() as u32 >= MAX_TIMED_PASSES {
            *self.untimed.borrow_mut() += 1;
            return None;
        }
        let slot = 2 * labels.len() as u32;
        labels.push(label.to_string());
        Some((qs, slot))
    }

    /// Timestamp writes for the next render pass (`None` without timestamps).
    pub fn render(&self, label: &str) -> Option<wgpu::RenderPassTimestampWrites<'_>> {
        self.next_slot(label)
            .map(|(query_set, i)| wgpu::RenderPassTimestampWrites {
                query_set,
                beginning_of_pass_write_index: Some(i),
                end_of_pass_write_index: Some(i + 1),
            })
    }

    /// Timestamp writes for the next compute pass (`None` without timestamps).
    pub fn compute(&self, label: &str) -> Option<wgpu::ComputePassTimestampWrites<'_>> {
        self.next_slot(label)
            .map(|(query_set, i)| wgpu::ComputePassTimestampWrites {
                query_set,
                beginning_of_pass_write_index: Some(i),
                end_of_pass_write_index: Some(i + 1),
            })
    }

    pub(crate) fn used(&self) -> u32 {
        self.labels.borrow().len() as u32
    }

    pub(crate) fn untimed(&self) -> u32 {
        *self.untimed.borrow()
    }

    pub(crate) fn labels(&self) -> Vec<String> {
        self.labels.borrow().clone()
    }

    pub(crate) fn query_set(&self) -> Option<&wgpu::QuerySet> {
        self.query_set.as_ref()
    }
}

/// Summary statistics of a series of ms values.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct Stats {
    pub mean: f64,
    pub median: f64,
    pub min: f64,
    pub max: f64,
}

impl Stats {
    /// `None` for an empty series.
    pub fn of(values: &[f64]) -> Option<Self> {
        if values.is_empty() {
            return None;
        }
        let mut v = values.to_vec();
        v.sort_by(f64::total_cmp);
        let n = v.len();
        let median = if n % 2 == 1 {
            v[n / 2]
        } else {
            0.5 * (v[n / 2 - 1] + v[n / 2])
        };
        Some(Stats {
            mean: v.iter().sum::<f64>() / n as f64,
            median,
            min: v[0],
            max: v[n - 1],
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn stats_of_a_series() {
        assert_eq!(Stats::of(&[]), None);
        let s = Stats::of(&[3.0, 1.0, 2.0, 10.0]).unwrap();
        assert_eq!((s.mean, s.median, s.min, s.max), (4.0, 2.5, 1.0, 10.0));
    }
}
