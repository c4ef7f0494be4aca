//! Measures that survive chaos. Where the trajectory itself is chaotic over the horizon
//! (a cloth folding on a sphere: the reference cannot agree with itself about where each
//! particle is), the report judges runs by the cloth's shape in aggregate instead: where its
//! mass is, how spread it is, how stretched its springs are.

use glam::DVec3;

use crate::cloth::ClothModel;
use crate::mesh::SpringKind;

use super::measure::Trajectory;

/// What the report judges runs by.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize)]
pub enum Judged {
    /// Each particle's position against the reference's, along the trajectory.
    #[default]
    Trajectory,
    /// The shape in aggregate ([`ShapeStats`]) against the reference's: the trajectory is
    /// chaotic over the horizon.
    Shape,
}

/// The cloth's shape in aggregate at one time.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ShapeStats {
    /// Centre of mass, metres.
    pub centre: DVec3,
    /// Radius of gyration about it, metres.
    pub spread: f64,
    /// Mean relative extension of the structural springs.
    pub mean_strain: f64,
}

impl ShapeStats {
    /// The stats of `model`'s cloth at `pos`.
    pub fn of(model: &ClothModel, pos: &[DVec3]) -> Self {
        let mass: f64 = model.mass.iter().map(|&m| m as f64).sum::<f64>().max(1e-30);
        let weighted = |f: &dyn Fn(usize) -> f64| {
            (0..pos.len())
                .map(|i| model.mass[i] as f64 * f(i))
                .sum::<f64>()
                / mass
        };
        let centre = DVec3::new(
            weighted(&|i| pos[i].x),
            weighted(&|i| pos[i].y),
            weighted(&|i| pos[i].z),
        );
        let spread = weighted(&|i| pos[i].distance_squared(centre)).sqrt();
        let s = &model.springs;
        let structural: Vec<f64> = (0..s.len())
            .filter(|&e| s.kind[e] == SpringKind::Structural && s.rest[e] > 0.0)
            .map(|e| pos[s.a[e] as usize].distance(pos[s.b[e] as usize]) / s.rest[e] as f64 - 1.0)
            .collect();
        let mean_strain = if structural.is_empty() {
            0.0
        } else {
            structural.iter().sum::<f64>() / structural.len() as f64
        };
        Self {
            centre,
            spread,
            mean_strain,
        }
    }
}

/// How far `run`'s shape is from `reference`'s sampled at the same times: the largest over
/// the samples of the centre of mass's distance and the spread's difference (fraction of
/// the cloth's `size`), and of the mean strains' difference. Infinite when the run did not
/// finish.
pub fn shape_error(
    model: &ClothModel,
    run: &Trajectory,
    reference: &Trajectory,
    size: f64,
) -> (f64, f64) {
    if !run.finite || run.positions.len() != reference.positions.len() {
        return (f64::INFINITY, f64::INFINITY);
    }
    let (mut shape, mut strain) = (0.0f64, 0.0f64);
    for (x, r) in run.positions.iter().zip(&reference.positions) {
        let (a, b) = (ShapeStats::of(model, x), ShapeStats::of(model, r));
        let moved = a.centre.distance(b.centre);
        let spread = (a.spread - b.spread).abs();
        shape = shape.max(moved.max(spread) / size);
        strain = strain.max((a.mean_strain - b.mean_strain).abs());
    }
    (shape, strain)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cloth::Springs;
    use glam::Vec3;

    /// Two unit masses 2 m apart on a spring of rest length 1: centre midway, spread 1 m,
    /// strain 1; moved 3 m up as a whole, only the centre moves.
    #[test]
    fn the_stats_of_a_stretched_pair_and_how_far_a_moved_copy_is() {
        let mut springs = Springs::default();
        springs.a.push(0);
        springs.b.push(1);
        springs.rest.push(1.0);
        springs.kind.push(SpringKind::Structural);
        let pos = vec![Vec3::ZERO, Vec3::new(2.0, 0.0, 0.0)];
        let model = ClothModel::from_springs(pos.clone(), springs, vec![1.0, 1.0], &[]);
        let wide: Vec<DVec3> = pos.iter().map(|p| p.as_dvec3()).collect();
        let stats = ShapeStats::of(&model, &wide);
        assert_eq!(stats.centre, DVec3::new(1.0, 0.0, 0.0));
        assert!((stats.spread - 1.0).abs() < 1e-6);
        assert!((stats.mean_strain - 1.0).abs() < 1e-6);
        let trajectory = |p: Vec<Vec3>| Trajectory {
            positions: vec![p.iter().map(|p| p.as_dvec3()).collect()],
            ..Trajectory::empty(crate::sim::IntegratorKind::Rk4)
        };
        let up: Vec<Vec3> = pos.iter().map(|p| *p + Vec3::Y * 3.0).collect();
        let (shape, strain) = shape_error(&model, &trajectory(up), &trajectory(pos), 2.0);
        assert!((shape - 1.5).abs() < 1e-6, "{shape}");
        assert_eq!(strain, 0.0);
    }
}
