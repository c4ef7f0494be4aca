//! Every force term's derivatives against central finite differences of its forces, and the
//! implicit system assembled from them.

use glam::Vec3;

use super::{Force, ForceSet, JacobianMode, SpringForce, SystemMatrix};
use crate::cloth::ClothModel;
use crate::mesh::{GridOrientation, GridSpec};
use crate::sim::effects::{AirDamping, Gravity};
use crate::sim::kernels::{Components, split};

/// A small deterministic generator (xorshift), so the tests need no dependency.
struct Rng(u64);

impl Rng {
    fn unit(&mut self) -> f32 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        (self.0 >> 40) as f32 / (1u64 << 24) as f32 * 2.0 - 1.0
    }

    fn vec(&mut self, scale: f32) -> Vec3 {
        Vec3::new(self.unit(), self.unit(), self.unit()) * scale
    }

    fn vecs(&mut self, n: usize, scale: f32) -> Vec<Vec3> {
        (0..n).map(|_| self.vec(scale)).collect()
    }
}

/// A 5 × 5-particle cloth, 0.3 m wide, one corner pinned (spacing 7.5 cm).
fn small_cloth() -> ClothModel {
    let mesh = GridSpec::square(4, 0.3, GridOrientation::Horizontal, Vec3::ZERO)
        .build()
        .unwrap();
    ClothModel::new(&mesh, 0.2, &[0])
}

/// A random state: positions jittered by up to 3 cm about the rest shape (so some springs
/// are compressed and some stretched) and velocities up to 1 m/s.
fn random_state(model: &ClothModel, rng: &mut Rng) -> (Vec<Vec3>, Vec<Vec3>) {
    let pos = model
        .rest_positions
        .iter()
        .map(|&p| p + rng.vec(0.03))
        .collect();
    (pos, rng.vecs(model.particle_count(), 1.0))
}

/// The springs, with damping well above the defaults, so the dashpot's direction term
/// matters.
fn spring_term(model: &ClothModel) -> SpringForce {
    SpringForce::new(&model.springs, [400.0, 150.0, 20.0], [0.5, 0.3, 0.1])
}

fn springs(model: &ClothModel) -> Force {
    Force::new("springs", spring_term(model))
}

fn every_term(model: &ClothModel) -> Vec<Force> {
    vec![
        Force::new("gravity", Gravity::default()),
        springs(model),
        Force::new("air-damping", AirDamping { rate: 0.7 }),
    ]
}

fn norm(v: &[Vec3]) -> f32 {
    v.iter().map(|x| x.length_squared()).sum::<f32>().sqrt()
}

fn difference(a: &[Vec3], b: &[Vec3]) -> f32 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (*x - *y).length_squared())
        .sum::<f32>()
        .sqrt()
}

/// Which argument a finite difference perturbs.
#[derive(Clone, Copy)]
enum Wrt {
    Position,
    Velocity,
}

/// `(f(s + εu) − f(s − εu)) / 2ε` with `s` the positions or the velocities.
///
/// The step sizes balance truncation against f32 rounding. In position, ε = 0.1 mm against
/// a spacing of 7.5 cm leaves a truncation error near 1e-6. The forces are linear in the
/// velocities, so there a larger ε = 1 cm/s has no truncation error and keeps the change in
/// the (elastic-dominated) force well above its rounding.
fn central_difference(
    set: &ForceSet,
    model: &ClothModel,
    (pos, vel): (&[Vec3], &[Vec3]),
    u: &[Vec3],
    wrt: Wrt,
) -> Vec<Vec3> {
    let eps = match wrt {
        Wrt::Position => 1e-4,
        Wrt::Velocity => 1e-2,
    };
    let shifted = |base: &[Vec3], sign: f32| -> Vec<Vec3> {
        base.iter()
            .zip(u)
            .map(|(b, d)| *b + sign * eps * *d)
            .collect()
    };
    let (mut plus, mut minus) = (Vec::new(), Vec::new());
    match wrt {
        Wrt::Position => {
            set.forces(model, &shifted(pos, 1.0), vel, &mut plus);
            set.forces(model, &shifted(pos, -1.0), vel, &mut minus);
        }
        Wrt::Velocity => {
            set.forces(model, pos, &shifted(vel, 1.0), &mut plus);
            set.forces(model, pos, &shifted(vel, -1.0), &mut minus);
        }
    }
    plus.iter()
        .zip(&minus)
        .map(|(p, m)| (*p - *m) / (2.0 * eps))
        .collect()
}

/// Relative error of the analytic action against finite differences (absolute when the
/// derivative is zero), over `trials` random states and directions.
fn worst_error(terms: Vec<Force>, wrt: Wrt, mode: JacobianMode, trials: u64) -> f32 {
    let model = small_cloth();
    let set = ForceSet::from_terms(terms);
    let mut worst = 0.0f32;
    for seed in 1..=trials {
        let mut rng = Rng(0x9E37_79B9_7F4A_7C15 ^ seed);
        let (pos, vel) = random_state(&model, &mut rng);
        let u = rng.vecs(model.particle_count(), 1.0);
        let fd = central_difference(&set, &model, (&pos, &vel), &u, wrt);
        let mut analytic = Vec::new();
        match wrt {
            Wrt::Position => set.df_dx(&model, &pos, &vel, &u, mode, &mut analytic),
            Wrt::Velocity => set.df_dv(&model, &pos, &vel, &u, &mut analytic),
        }
        let scale = norm(&fd).max(norm(&analytic));
        let err = difference(&fd, &analytic);
        worst = worst.max(if scale > 1e-3 { err / scale } else { err });
    }
    worst
}

#[test]
fn spring_position_derivative_matches_finite_differences() {
    let err = worst_error(
        vec![springs(&small_cloth())],
        Wrt::Position,
        JacobianMode::Exact,
        20,
    );
    assert!(err <= 1e-3, "relative error {err}");
}

#[test]
fn spring_velocity_derivative_matches_finite_differences() {
    let err = worst_error(
        vec![springs(&small_cloth())],
        Wrt::Velocity,
        JacobianMode::Exact,
        20,
    );
    assert!(err <= 1e-3, "relative error {err}");
}

#[test]
fn air_damping_derivatives_match_finite_differences() {
    let term = || vec![Force::new("air-damping", AirDamping { rate: 0.7 })];
    let err = worst_error(term(), Wrt::Velocity, JacobianMode::Exact, 10);
    assert!(err <= 1e-3, "∂f/∂v relative error {err}");
    let err = worst_error(term(), Wrt::Position, JacobianMode::Exact, 10);
    assert!(err <= 1e-6, "∂f/∂x must be zero, differs by {err}");
}

#[test]
fn gravity_has_zero_derivatives() {
    let term = || vec![Force::new("gravity", Gravity::default())];
    for wrt in [Wrt::Position, Wrt::Velocity] {
        let err = worst_error(term(), wrt, JacobianMode::Exact, 5);
        assert!(
            err <= 1e-6,
            "gravity's derivative must be zero, differs by {err}"
        );
    }
}

#[test]
fn every_term_together_matches_finite_differences() {
    let model = small_cloth();
    for wrt in [Wrt::Position, Wrt::Velocity] {
        let err = worst_error(every_term(&model), wrt, JacobianMode::Exact, 20);
        assert!(err <= 1e-3, "relative error {err}");
    }
}

/// The definite form leaves out real terms (compressed springs' negative transverse
/// stiffness, the dashpot's direction change): at these states the finite differences
/// tell it apart from the exact derivative, which shows they are a sharp test.
#[test]
fn the_definite_form_is_not_the_exact_derivative() {
    let err = worst_error(
        vec![springs(&small_cloth())],
        Wrt::Position,
        JacobianMode::Definite,
        20,
    );
    assert!(
        err > 1e-2,
        "definite form matched the exact derivative: {err}"
    );
}

/// For a stretched spring whose ends move together both forms agree.
#[test]
fn both_forms_agree_for_stretched_springs_at_rest() {
    let model = small_cloth();
    let s = spring_term(&model);
    let pos: Vec<Vec3> = model.rest_positions.iter().map(|&p| p * 1.1).collect();
    let vel = vec![Vec3::new(0.3, -0.2, 0.1); model.particle_count()];
    for e in 0..model.springs.len() {
        let exact = s.blocks::<f32>(&model.springs, &pos, &vel, e, JacobianMode::Exact);
        let definite = s.blocks::<f32>(&model.springs, &pos, &vel, e, JacobianMode::Definite);
        assert!(exact.dx.abs_diff_eq(definite.dx, 1e-3), "spring {e}");
    }
}

/// `A = M − h·∂f/∂v − h²·∂f/∂x` assembled at a random state.
fn assembled(h: f32) -> (ClothModel, SystemMatrix, Vec<Vec3>, Vec<Vec3>) {
    let model = small_cloth();
    let set = ForceSet::from_terms(every_term(&model));
    let (pos, vel) = random_state(&model, &mut Rng(42));
    let mut sys = SystemMatrix::default();
    set.assemble(&model, &pos, &vel, h, &mut sys);
    (model, sys, pos, vel)
}

#[test]
fn the_system_matrix_is_symmetric() {
    let (model, sys, _, _) = assembled(1e-3);
    let a = sys.dense(&model.springs);
    let largest = a.iter().flatten().fold(0.0f64, |m, x| m.max(x.abs()));
    for (i, row) in a.iter().enumerate() {
        for (j, &aij) in row.iter().enumerate().take(i) {
            assert!(
                (aij - a[j][i]).abs() <= 1e-6 * largest,
                "A[{i}][{j}] = {aij} but A[{j}][{i}] = {}",
                a[j][i]
            );
        }
    }
}

#[test]
fn the_system_matrix_is_positive_definite() {
    // Cholesky succeeds exactly for symmetric positive definite matrices; a large step
    // makes the stiffness part dominate the mass.
    let (model, sys, _, _) = assembled(0.05);
    let mut a = sys.dense(&model.springs);
    let n = a.len();
    for j in 0..n {
        let d = a[j][j] - (0..j).map(|k| a[j][k] * a[j][k]).sum::<f64>();
        assert!(d > 0.0, "pivot {j} is {d}: not positive definite");
        a[j][j] = d.sqrt();
        for i in j + 1..n {
            let s = a[i][j] - (0..j).map(|k| a[i][k] * a[j][k]).sum::<f64>();
            a[i][j] = s / a[j][j];
        }
    }
}

#[test]
fn the_system_matrix_is_mass_minus_h_dfdv_minus_h2_dfdx() {
    let h = 2e-3;
    let (model, sys, pos, vel) = assembled(h);
    let set = ForceSet::from_terms(every_term(&model));
    let u = Rng(7).vecs(model.particle_count(), 1.0);
    let (mut jx, mut jv, mut au) = (Vec::new(), Vec::new(), vec![Vec3::ZERO; u.len()]);
    set.df_dx(&model, &pos, &vel, &u, JacobianMode::Definite, &mut jx);
    set.df_dv(&model, &pos, &vel, &u, &mut jv);
    sys.apply(&model, &u, &mut au);
    let expected: Vec<Vec3> = (0..u.len())
        .map(|i| model.mass[i] * u[i] - h * jv[i] - h * h * jx[i])
        .collect();
    let err = difference(&au, &expected) / norm(&expected);
    assert!(err < 1e-5, "relative difference {err}");
    // So is the product on component arrays the linear solver multiplies with, also
    // after the matrix is assembled again at another step.
    let mut sys = sys;
    for (round, step) in [h, 3.0 * h].into_iter().enumerate() {
        set.assemble(&model, &pos, &vel, step, &mut sys);
        sys.apply(&model, &u, &mut au);
        let (mut uc, mut out) = <(Components, Components)>::default();
        split(&u, &mut uc, u.len());
        split(&u, &mut out, u.len());
        sys.apply_components(&uc, &mut out);
        let fast: Vec<Vec3> = (0..u.len())
            .map(|i| Vec3::new(out[0][i], out[1][i], out[2][i]))
            .collect();
        let err = difference(&fast, &au) / norm(&au);
        assert!(err < 1e-6, "round {round}: relative difference {err}");
    }
    set.assemble(&model, &pos, &vel, h, &mut sys);
    sys.apply(&model, &u, &mut au);
    // The dense form is the same operator.
    let dense = sys.dense(&model.springs);
    for (i, row) in dense.iter().enumerate() {
        let value: f64 = row
            .iter()
            .enumerate()
            .map(|(j, a)| a * u[j / 3][j % 3] as f64)
            .sum();
        assert!((value - au[i / 3][i % 3] as f64).abs() < 1e-4 * norm(&au) as f64);
    }
    // And the right-hand side's (∂f/∂x)·v is the definite action on the velocities.
    set.df_dx(&model, &pos, &vel, &vel, JacobianMode::Definite, &mut jx);
    let dfdx_v: Vec<Vec3> = (0..jx.len()).map(|i| sys.dfdx_v(i)).collect();
    assert!(difference(&dfdx_v, &jx) <= 1e-5 * norm(&jx));
}

/// The springs' plain path (the one `f64` takes) gives the vectorised runs' forces: in `f32`
/// the two agree to rounding (they sum in another order) on a jittered, moving cloth, and
/// in `f64` the plain path agrees with both to `f32`'s rounding.
#[test]
fn the_springs_plain_path_gives_the_runs_forces() {
    let model = small_cloth();
    let s = spring_term(&model);
    let (pos, vel) = random_state(&model, &mut Rng(0x5eed));
    let n = pos.len();
    let mut runs = vec![Vec3::ZERO; n];
    s.add_forces::<f32>(&model.springs, &pos, &vel, &mut runs);
    let mut plain = vec![Vec3::ZERO; n];
    s.add_forces_plain::<f32>(&model.springs, &pos, &vel, &mut plain);
    let wide = |v: &[Vec3]| -> Vec<glam::DVec3> { v.iter().map(|p| p.as_dvec3()).collect() };
    let mut precise = vec![glam::DVec3::ZERO; n];
    s.add_forces::<f64>(&model.springs, &wide(&pos), &wide(&vel), &mut precise);
    let largest = runs.iter().map(|f| f.length()).fold(0.0, f32::max);
    assert!(largest > 1.0, "a real load: {largest} N");
    for i in 0..n {
        let tolerance = 1e-5 * largest;
        assert!(
            runs[i].distance(plain[i]) < tolerance,
            "{i}: {} {}",
            runs[i],
            plain[i]
        );
        let gap = runs[i].as_dvec3().distance(precise[i]) as f32;
        assert!(
            gap < tolerance,
            "{i}: f64 {} against {}",
            precise[i],
            runs[i]
        );
    }
}
