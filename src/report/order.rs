//! The order of accuracy a sweep observed: how fast each method's error falls with its step.

/// Errors above this fraction of the cloth's size are not taken for the order: so far from
/// the answer a method is not yet in its asymptotic range (its error not yet ∝ hᵖ).
pub const ASYMPTOTIC_ERROR: f64 = 0.1;

/// An error counts as resolved when it is at least this many times the reference's
/// uncertainty (below, the reference's own error would be measured).
pub const RESOLVED: f64 = 10.0;

/// The order a method showed.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct ObservedOrder {
    /// The least-squares slope of log error over log step.
    pub order: f64,
    /// Decades of error the fitted points span.
    pub decades: f64,
    /// How many points were fitted.
    pub points: usize,
}

/// The order from `(step, max error)` pairs of one method's stable, resolved runs, fitted
/// over those in the asymptotic range (error at most [`ASYMPTOTIC_ERROR`]); `None` with
/// fewer than two such steps.
pub fn observed_order(runs: &[(f64, f64)]) -> Option<ObservedOrder> {
    let fitted: Vec<(f64, f64)> = runs
        .iter()
        .filter(|(dt, e)| dt.is_finite() && *dt > 0.0 && e.is_finite())
        .filter(|(_, e)| *e > 0.0 && *e <= ASYMPTOTIC_ERROR)
        .map(|&(dt, e)| (dt.ln(), e.ln()))
        .collect();
    let order = slope(&fitted)?;
    let (lo, hi) = fitted
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), p| {
            (lo.min(p.1), hi.max(p.1))
        });
    Some(ObservedOrder {
        order,
        decades: (hi - lo) / std::f64::consts::LN_10,
        points: fitted.len(),
    })
}

/// The least-squares slope of `y` over `x` through `points`; `None` with fewer than two
/// distinct `x`.
pub fn slope(points: &[(f64, f64)]) -> Option<f64> {
    let n = points.len() as f64;
    if points.len() < 2 {
        return None;
    }
    let mean = |f: fn(&(f64, f64)) -> f64| points.iter().map(f).sum::<f64>() / n;
    let (mx, my) = (mean(|p| p.0), mean(|p| p.1));
    let sxx: f64 = points.iter().map(|p| (p.0 - mx).powi(2)).sum();
    let sxy: f64 = points.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum();
    (sxx > 0.0).then(|| sxy / sxx)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Errors `c·hᵖ` over steps halving: the fit recovers `p` and the span, and leaves out
    /// the errors above 10 %.
    #[test]
    fn the_fit_recovers_the_order_of_clean_errors_in_the_asymptotic_range() {
        let runs: Vec<(f64, f64)> = (0..8)
            .map(|i| {
                let h = 1e-2 / 2f64.powi(i);
                (h, 300.0 * h.powi(2))
            })
            .collect();
        // Errors 3e-2 … 1.8e-6, a quarter each: eight points, seven quarterings.
        let fit = observed_order(&runs).unwrap();
        assert!((fit.order - 2.0).abs() < 1e-9, "{fit:?}");
        assert_eq!(fit.points, 8);
        assert!((fit.decades - 7.0 * 4f64.log10()).abs() < 1e-9, "{fit:?}");
        // Everything above 10 % is left out: a first point at 50 % would bend the fit.
        let mut bent = runs.clone();
        bent.insert(0, (2e-2, 0.5));
        assert_eq!(observed_order(&bent), Some(fit));
        assert_eq!(observed_order(&runs[..1]), None);
    }
}
