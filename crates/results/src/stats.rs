//! Summary statistics of frame samples and the 95 % interval of a mean over views.

use crate::Timing;

pub fn mean(xs: &[f64]) -> Option<f64> {
    if xs.is_empty() {
        None
    } else {
        Some(xs.iter().sum::<f64>() / xs.len() as f64)
    }
}

/// Median (mean of the middle two for an even count). NaNs sort last.
pub fn median(xs: &[f64]) -> Option<f64> {
    if xs.is_empty() {
        return None;
    }
    let mut v = xs.to_vec();
    v.sort_by(f64::total_cmp);
    let n = v.len();
    Some(if n % 2 == 1 {
        v[n / 2]
    } else {
        0.5 * (v[n / 2 - 1] + v[n / 2])
    })
}

/// Sample variance (n - 1); zero for fewer than two samples.
pub fn variance(xs: &[f64]) -> f64 {
    let Some(m) = mean(xs) else { return 0.0 };
    if xs.len() < 2 {
        return 0.0;
    }
    xs.iter().map(|x| (x - m) * (x - m)).sum::<f64>() / (xs.len() - 1) as f64
}

/// Mean / median / min / max with the samples kept. None for no samples.
pub fn summarize(samples: &[f64]) -> Option<Timing> {
    Some(Timing {
        mean: mean(samples)?,
        median: median(samples)?,
        min: samples.iter().copied().fold(f64::INFINITY, f64::min),
        max: samples.iter().copied().fold(f64::NEG_INFINITY, f64::max),
        samples: samples.to_vec(),
    })
}

/// The mean over views of each view's frame mean, and the half-width of its
/// 95 % interval: `1.96 sqrt(sum_v s_v² / n_v) / V`, the normal interval of
/// a mean of independent per-view means (the paper's within-session interval;
/// with equal variances this is `1.96 sd / sqrt(n)` over all V·n samples).
pub fn mean_of_means_interval(per_view_samples: &[&[f64]]) -> Option<(f64, f64)> {
    let views: Vec<&[f64]> = per_view_samples
        .iter()
        .copied()
        .filter(|s| !s.is_empty())
        .collect();
    if views.is_empty() {
        return None;
    }
    let v = views.len() as f64;
    let grand = views.iter().map(|s| mean(s).unwrap_or(0.0)).sum::<f64>() / v;
    let var_sum: f64 = views.iter().map(|s| variance(s) / s.len() as f64).sum();
    Some((grand, 1.96 * var_sum.sqrt() / v))
}

/// Nearest-rank percentile (`q` in [0, 1]) of finite values; None if there are none.
pub fn percentile(xs: &[f64], q: f64) -> Option<f64> {
    let mut v: Vec<f64> = xs.iter().copied().filter(|x| x.is_finite()).collect();
    if v.is_empty() {
        return None;
    }
    v.sort_by(f64::total_cmp);
    let rank = (q.clamp(0.0, 1.0) * v.len() as f64).ceil() as usize;
    Some(v[rank.saturating_sub(1).min(v.len() - 1)])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn summary_of_known_samples() {
        let t = summarize(&[4.0, 1.0, 3.0, 2.0]).unwrap();
        assert_eq!((t.mean, t.median, t.min, t.max), (2.5, 2.5, 1.0, 4.0));
        assert_eq!(median(&[3.0, 1.0, 2.0]), Some(2.0));
        assert!(summarize(&[]).is_none());
        assert!((variance(&[1.0, 2.0, 3.0, 4.0]) - 5.0 / 3.0).abs() < 1e-12);
    }

    #[test]
    fn interval_matches_the_pooled_formula_for_equal_spread() {
        // Two views, each 1,3 (sd sqrt 2, n 2): half-width 1.96 sqrt(2*2/2)/2.
        let a = [1.0, 3.0];
        let b = [11.0, 13.0];
        let (m, h) = mean_of_means_interval(&[&a, &b]).unwrap();
        assert!((m - 7.0).abs() < 1e-12);
        assert!((h - 1.96 * 2f64.sqrt() / 2.0).abs() < 1e-12, "{h}");
        // Constant samples: zero width.
        let (_, h) = mean_of_means_interval(&[&[5.0, 5.0, 5.0]]).unwrap();
        assert_eq!(h, 0.0);
        assert!(mean_of_means_interval(&[]).is_none());
    }

    #[test]
    fn percentile_is_nearest_rank() {
        let xs: Vec<f64> = (1..=100).map(f64::from).collect();
        assert_eq!(percentile(&xs, 0.95), Some(95.0));
        assert_eq!(percentile(&xs, 0.5), Some(50.0));
        assert_eq!(percentile(&[f64::INFINITY], 0.5), None);
    }
}
