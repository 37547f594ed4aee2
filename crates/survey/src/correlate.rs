//! Pearson correlation, as the paper reports it.

/// Pearson's r of paired samples; `None` with fewer than three pairs or when
/// either side is constant (no variation, no correlation to speak of).
pub fn pearson(pairs: &[(f64, f64)]) -> Option<f64> {
    let n = pairs.len();
    if n < 3 {
        return None;
    }
    let mean = |f: fn(&(f64, f64)) -> f64| pairs.iter().map(f).sum::<f64>() / n as f64;
    let (mx, my) = (mean(|p| p.0), mean(|p| p.1));
    let (mut sxy, mut sxx, mut syy) = (0.0, 0.0, 0.0);
    for &(x, y) in pairs {
        sxy += (x - mx) * (y - my);
        sxx += (x - mx) * (x - mx);
        syy += (y - my) * (y - my);
    }
    let d = (sxx * syy).sqrt();
    (d > 1e-12 * (1.0 + sxx + syy)).then(|| sxy / d)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn known_values() {
        let line: Vec<_> = (0..5)
            .map(|i| (f64::from(i), 3.0 - 2.0 * f64::from(i)))
            .collect();
        assert!((pearson(&line).unwrap() + 1.0).abs() < 1e-12);
        // x = 1..5, y = 2, 4, 5, 4, 5: r = 0.7746 (textbook example).
        let pts = [(1.0, 2.0), (2.0, 4.0), (3.0, 5.0), (4.0, 4.0), (5.0, 5.0)];
        assert!((pearson(&pts).unwrap() - 0.774_596_669).abs() < 1e-6);
        assert_eq!(pearson(&[(1.0, 1.0), (2.0, 2.0)]), None);
        assert_eq!(pearson(&[(1.0, 1.0), (1.0, 2.0), (1.0, 3.0)]), None);
    }
}
