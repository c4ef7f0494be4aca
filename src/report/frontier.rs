//! The cost–accuracy frontier and the choice made from it.

use super::point::Point;

/// Indices of the stable, resolved points on the Pareto frontier, cheapest first: each is
/// more accurate (smaller maximum error) than every cheaper one. An unresolved error (near
/// the reference's uncertainty or the run's rounding) cannot rank a point. Cheaper by counted
/// work ([`Point::work_per_sim_s`]), never by wall time: the same points give the same
/// frontier on every run.
pub fn frontier(points: &[Point]) -> Vec<usize> {
    let mut stable: Vec<usize> = (0..points.len())
        .filter(|&i| points[i].stable && points[i].resolved)
        .collect();
    stable.sort_by(|&a, &b| {
        let (pa, pb) = (&points[a], &points[b]);
        pa.work_per_sim_s
            .total_cmp(&pb.work_per_sim_s)
            .then(pa.max_error.total_cmp(&pb.max_error))
    });
    let mut best = f64::INFINITY;
    let mut out = Vec::new();
    for i in stable {
        if points[i].max_error < best {
            best = points[i].max_error;
            out.push(i);
        }
    }
    out
}

/// Counted costs this close (as a fraction) are one cost to the model: its unit costs are
/// rounded measurements, good to a few per cent.
pub const COST_RESOLUTION: f64 = 0.05;

/// The cheapest frontier point whose maximum error is within `tolerance` (relative to the
/// cloth's size), if any; of the frontier points within the tolerance that cost at most
/// [`COST_RESOLUTION`] more than it, the most accurate (the model cannot tell their costs
/// apart, and the errors differ). A pure function of the points: the same points give the
/// same choice.
pub fn recommend(points: &[Point], frontier: &[usize], tolerance: f64) -> Option<usize> {
    let within = |i: &usize| points[*i].max_error <= tolerance;
    let cheapest = frontier.iter().copied().find(within)?;
    let budget = points[cheapest].work_per_sim_s * (1.0 + COST_RESOLUTION);
    (frontier.iter().copied())
        .filter(|i| within(i) && points[*i].work_per_sim_s <= budget)
        .min_by(|&a, &b| points[a].max_error.total_cmp(&points[b].max_error))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_frontier_keeps_only_undominated_stable_points() {
        let points = [
            Point::at(1.0, 0.1, true),
            Point::at(2.0, 0.2, true), // dearer and worse than the first: dominated
            Point::at(3.0, 0.01, true),
            Point::at(0.5, 1e-9, false), // cheap and exact, but unstable
            Point::at(4.0, 0.001, true),
            Point {
                resolved: false, // its error is within the reference's uncertainty
                ..Point::at(5.0, 1e-7, true)
            },
        ];
        assert_eq!(frontier(&points), vec![0, 2, 4]);
    }

    #[test]
    fn the_choice_is_the_cheapest_point_within_tolerance() {
        let points = [
            Point::at(1.0, 0.1, true),
            Point::at(3.0, 0.01, true),
            Point::at(4.0, 0.001, true),
        ];
        let f = frontier(&points);
        assert_eq!(recommend(&points, &f, 0.05), Some(1));
        assert_eq!(recommend(&points, &f, 0.5), Some(0));
        assert_eq!(recommend(&points, &f, 1e-4), None);
    }

    /// The choice goes by counted work: `Point::at` gives each point a wall time that
    /// runs the other way, so choosing by it would pick the dearest.
    #[test]
    fn the_choice_is_made_by_counted_work_not_wall_time() {
        let points = [Point::at(1.0, 0.1, true), Point::at(3.0, 0.01, true)];
        assert!(points[1].wall_s_per_sim_s < points[0].wall_s_per_sim_s);
        let f = frontier(&points);
        assert_eq!(f, vec![0, 1]);
        assert_eq!(recommend(&points, &f, 0.5), Some(0));
    }

    /// Two points the model cannot tell apart by cost (within 5 %): the more accurate one.
    #[test]
    fn of_two_points_the_model_cannot_tell_apart_by_cost_the_more_accurate_is_chosen() {
        let points = [
            Point::at(100.0, 3e-4, true),
            Point::at(104.0, 5e-5, true),
            Point::at(106.0, 1e-5, true),
        ];
        let f = frontier(&points);
        assert_eq!(recommend(&points, &f, 1e-3), Some(1));
        // Beyond the resolution, the cheaper.
        let apart = [Point::at(100.0, 3e-4, true), Point::at(106.0, 1e-5, true)];
        assert_eq!(recommend(&apart, &frontier(&apart), 1e-3), Some(0));
    }
}
