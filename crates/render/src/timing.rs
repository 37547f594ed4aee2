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
    pub passes: PassTimes,
    /// Passes beyond [`MAX_TIMED_PASSES`] that ran untimed.
    pub untimed_passes: u32,
}

/// Each timed pass's label and GPU ms, in recording order.
pub type PassTimes = Vec<(String, f64)>;

/// Hands out timestamp slots to the passes of one frame, then resolves and
/// reads them back: `reset`, passes take `render` / `compute` writes,
/// `resolve` into the frame's encoder, submit and wait, `read`.
pub struct PassTimer {
    query_set: Option<wgpu::QuerySet>,
    /// Resolve target and mappable copy of the stamps.
    buffers: Option<(wgpu::Buffer, wgpu::Buffer)>,
    /// Nanoseconds per tick.
    period_ns: f64,
    labels: RefCell<Vec<String>>,
    untimed: RefCell<u32>,
}

impl PassTimer {
    /// A timer over `queue`'s clock; without `enabled` (the adapter has no
    /// timestamp queries) every pass runs untimed.
    pub fn new(device: &wgpu::Device, queue: &wgpu::Queue, enabled: bool) -> Self {
        let query_set = enabled.then(|| {
            device.create_query_set(&wgpu::QuerySetDescriptor {
                label: Some("pass timestamps"),
                ty: wgpu::QueryType::Timestamp,
                count: 2 * MAX_TIMED_PASSES,
            })
        });
        let buffers = enabled.then(|| {
            let size = u64::from(2 * MAX_TIMED_PASSES) * 8;
            let buffer = |label, usage| {
                device.create_buffer(&wgpu::BufferDescriptor {
                    label: Some(label),
                    size,
                    usage,
                    mapped_at_creation: false,
                })
            };
            use wgpu::BufferUsages as U;
            (
                buffer("timestamps resolve", U::QUERY_RESOLVE | U::COPY_SRC),
                buffer("timestamps read", U::MAP_READ | U::COPY_DST),
            )
        });
        PassTimer {
            query_set,
            buffers,
            period_ns: f64::from(queue.get_timestamp_period()),
            labels: RefCell::new(Vec::new()),
            untimed: RefCell::new(0),
        }
    }

    /// Copy this frame's stamps out (after its last timed pass).
    pub fn resolve(&self, encoder: &mut wgpu::CommandEncoder) {
        let used = self.used();
        if let (Some((resolve, read)), Some(qs)) = (&self.buffers, &self.query_set)
            && used > 0
        {
            encoder.resolve_query_set(qs, 0..2 * used, resolve, 0);
            encoder.copy_buffer_to_buffer(resolve, 0, read, 0, u64::from(2 * used) * 8);
        }
    }

    /// Each timed pass's label and GPU ms, and their sum (`None` without
    /// timestamps). Call after the frame's work has finished.
    pub fn read(
        &self,
        device: &wgpu::Device,
        errors: &crate::gpu::ErrorSink,
    ) -> anyhow::Result<(Option<f64>, PassTimes)> {
        let used = self.used();
        let Some((_, read)) = self.buffers.as_ref().filter(|_| used > 0) else {
            return Ok((None, Vec::new()));
        };
        let raw = crate::gpu::read_buffer(device, errors, read, u64::from(2 * used) * 8)?;
        let ticks: &[u64] = bytemuck::cast_slice(&raw);
        let passes: PassTimes = self
            .labels()
            .into_iter()
            .zip(ticks.chunks_exact(2))
            .map(|(label, t)| {
                (
                    label,
                    t[1].wrapping_sub(t[0]) as f64 * self.period_ns * 1e-6,
                )
            })
            .collect();
        Ok((Some(passes.iter().map(|p| p.1).sum()), passes))
    }

    /// This frame's summed GPU ms, waiting for the stamps (a method's own
    /// timer, outside the frame's sum). `None` without timestamps, and in a
    /// browser, where a read-back completes only after the page yields.
    pub fn read_blocking(&self, device: &wgpu::Device) -> anyhow::Result<Option<f64>> {
        if cfg!(target_arch = "wasm32") {
            return Ok(None);
        }
        Ok(self.read(device, &crate::gpu::ErrorSink::default())?.0)
    }

    /// Start a frame: no pass timed yet.
    pub fn reset(&self) {
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

    /// Passes beyond [`MAX_TIMED_PASSES`] this frame.
    pub fn untimed(&self) -> u32 {
        *self.untimed.borrow()
    }

    pub(crate) fn labels(&self) -> Vec<String> {
        self.labels.borrow().clone()
    }
}

/// Summary statistics of a series of ms values.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct Stats {
    /// Mean, ms.
    pub mean: f64,
    /// Median, ms.
    pub median: f64,
    /// Smallest, ms.
    pub min: f64,
    /// Largest, ms.
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
