//! The cost–accuracy frontier and the choice made from it.

use super::point::Point;

/// Indices of the stable points on the Pareto frontier, cheapest first: each is more
/// accurate than every cheaper one, by what its error is known to be below
/// ([`Point::error_bound`]: an error lost in the reference's uncertainty or the run's
/// rounding ranks at ten times that floor). Cheaper by counted work
/// ([`Point::work_per_sim_s`]), never by wall time: the same points give the same frontier
/// on every run.
pub fn frontier(points: &[Point]) -> Vec<usize> {
    let mut stable: Vec<usize> = (0..points.len()).filter(|&i| points[i].stable).collect();
    stable.sort_by(|&a, &b| {
        let (pa, pb) = (&points[a], &points[b]);
        (pa.work_per_sim_s.total_cmp(&pb.work_per_sim_s))
            .then(pa.error_bound().total_cmp(&pb.error_bound()))
    });
    let mut best = f64::INFINITY;
    let mut out = Vec::new();
    for i in stable {
        if points[i].error_bound() < best {
            best = points[i].error_bound();
            out.push(i);
        }
    }
    out
}

/// Counted costs this close (as a fraction) are one cost to the model: its unit costs are
/// rounded measurements, good to a few per cent.
pub const COST_RESOLUTION: f64 = 0.05;

/// The choice: of the stable points known to be within `tolerance` (relative to the cloth's
/// size; [`Point::error_bound`]) whose step the scene's frame holds a whole number of times
/// (what *Apply* can install), the cheapest by counted work; of those costing at most
/// [`COST_RESOLUTION`] more than it, the most accurate (the model cannot tell their costs
/// apart, and the errors differ). `None` if no point qualifies. A pure function of the
/// points: the same points give the same choice.
pub fn recommend(points: &[Point], tolerance: f64) -> Option<usize> {
    let eligible: Vec<usize> = (0..points.len())
        .filter(|&i| {
            let p = &points[i];
            p.stable && p.error_bound() <= tolerance && p.whole_substeps().is_some()
        })
        .collect();
    let by_work =
        |a: &usize, b: &usize| (points[*a].work_per_sim_s).total_cmp(&points[*b].work_per_sim_s);
    let cheapest = eligible.iter().copied().min_by(by_work)?;
    let budget = points[cheapest].work_per_sim_s * (1.0 + COST_RESOLUTION);
    (eligible.into_iter())
        .filter(|&i| points[i].work_per_sim_s <= budget)
        .min_by(|&a, &b| {
            (points[a].error_bound().total_cmp(&points[b].error_bound())).then(by_work(&a, &b))
        })
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
                // Its error is lost in a floor of 1e-4: known only to be below 1e-3.
                floor: 1e-4,
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
        assert_eq!(recommend(&points, 0.05), Some(1));
        assert_eq!(recommend(&points, 0.5), Some(0));
        assert_eq!(recommend(&points, 1e-4), None);
    }

    /// An error lost in the floor counts as ten times the floor: within a tolerance above
    /// that, such a point can be chosen; below it, not.
    #[test]
    fn an_unresolved_error_counts_as_ten_times_its_floor() {
        let points = [Point {
            floor: 1e-5,
            ..Point::at(1.0, 1e-6, true)
        }];
        assert_eq!(recommend(&points, 1e-3), Some(0));
        assert_eq!(recommend(&points, 5e-5), None);
    }

    /// A step the scene's frame does not hold a whole number of times (√2 substeps a frame)
    /// cannot be installed: the choice passes it over, cheap and accurate as it is.
    #[test]
    fn the_choice_is_a_step_the_frame_holds_a_whole_number_of_times() {
        let points = [
            Point {
                substeps_per_frame: std::f64::consts::SQRT_2,
                ..Point::at(1.0, 0.001, true)
            },
            Point::at(2.0, 0.005, true),
        ];
        assert_eq!(recommend(&points, 0.01), Some(1));
    }

    /// The choice goes by counted work: `Point::at` gives each point a wall time that
    /// runs the other way, so choosing by it would pick the dearest.
    #[test]
    fn the_choice_is_made_by_counted_work_not_wall_time() {
        let points = [Point::at(1.0, 0.1, true), Point::at(3.0, 0.01, true)];
        assert!(points[1].wall_s_per_sim_s < points[0].wall_s_per_sim_s);
        let f = frontier(&points);
        assert_eq!(f, vec![0, 1]);
        assert_eq!(recommend(&points, 0.5), Some(0));
    }

    /// Two points the model cannot tell apart by cost (within 5 %): the more accurate one.
    #[test]
    fn of_two_points_the_model_cannot_tell_apart_by_cost_the_more_accurate_is_chosen() {
        let points = [
            Point::at(100.0, 3e-4, true),
            Point::at(104.0, 5e-5, true),
            Point::at(106.0, 1e-5, true),
        ];
        assert_eq!(recommend(&points, 1e-3), Some(1));
        // Beyond the resolution, the cheaper.
        let apart = [Point::at(100.0, 3e-4, true), Point::at(106.0, 1e-5, true)];
        assert_eq!(recommend(&apart, 1e-3), Some(0));
    }
}
