//! The cost–accuracy frontier and the choice made from it.

use super::point::Point;

/// Indices of the stable points on the Pareto frontier, cheapest first: each is more
/// accurate (smaller maximum error) than every cheaper stable point.
pub fn frontier(points: &[Point]) -> Vec<usize> {
    let mut stable: Vec<usize> = (0..points.len()).filter(|&i| points[i].stable).collect();
    stable.sort_by(|&a, &b| {
        let (pa, pb) = (&points[a], &points[b]);
        pa.wall_s_per_sim_s
            .total_cmp(&pb.wall_s_per_sim_s)
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

/// The cheapest frontier point whose maximum error is within `tolerance` (relative to the
/// cloth's size), if any.
pub fn recommend(points: &[Point], frontier: &[usize], tolerance: f64) -> Option<usize> {
    frontier
        .iter()
        .copied()
        .find(|&i| points[i].max_error <= tolerance)
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
}
