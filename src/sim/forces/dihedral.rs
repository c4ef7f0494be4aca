//! Dihedral-angle bending, as in discrete shells: every interior edge is a hinge whose
//! energy `k·w·(θ − θ₀)²` grows with how far its dihedral angle θ is from its rest angle,
//! weighted by `w = 3|e|²/(A₁ + A₂)` of the rest geometry, so the bending stiffness does not
//! depend on the mesh's resolution.

use crate::cloth::{ClothModel, Real, Vector};

use super::force_term::ForceTerm;

mod lanes;
#[cfg(test)]
mod tests;

/// The hinges of a cloth with their rest angles and weights, and a stiffness (N·m).
#[derive(Clone, Debug, PartialEq)]
pub struct DihedralBending {
    stiffness: f32,
    rest: Vec<f32>,
    weight: Vec<f32>,
}

/// The signed dihedral angle of hinge `[x0, x1, a, b]` (radians, 0 when flat) and its
/// gradient with respect to the four points, or `None` for a degenerate hinge.
pub fn hinge_angle<R: Real>(x0: R::V3, x1: R::V3, a: R::V3, b: R::V3) -> Option<(R, [R::V3; 4])> {
    let e = x1 - x0;
    let len2 = e.length_squared();
    // Unnormalised normals of (x0, x1, a) and (x1, x0, b): equal when flat.
    let na = e.cross(a - x0);
    let nb = (x0 - x1).cross(b - x1);
    let (na2, nb2) = (na.length_squared(), nb.length_squared());
    let tiny = R::of_f32(1e-24);
    if len2 <= tiny || na2 <= tiny || nb2 <= tiny {
        return None;
    }
    let len = len2.sqrt();
    let axis = e / len;
    let theta = na.cross(nb).dot(axis).atan2(na.dot(nb));
    // Turning a wing about the edge turns its normal with it: ∂θ/∂a = −n_a·|e|/|n_a|²,
    // ∂θ/∂b = −n_b·|e|/|n_b|². The edge's ends take the rest so that the gradient sums to
    // zero and is unchanged by rotations (α: where each wing projects onto the edge).
    let ga = -na * (len / na2);
    let gb = -nb * (len / nb2);
    let alpha_a = (a - x0).dot(e) / len2;
    let alpha_b = (b - x0).dot(e) / len2;
    let one = R::ONE;
    let g0 = ga * (alpha_a - one) + gb * (alpha_b - one);
    let g1 = ga * (-alpha_a) - gb * alpha_b;
    Some((theta, [g0, g1, ga, gb]))
}

/// Wings lower than this fraction of their hinge's length get a limited force.
const MIN_WING: f32 = 0.02;

/// The factor (≤ 1) a hinge's force is scaled by so that no wing's part of the gradient
/// exceeds `1/(MIN_WING·|e|)`. A wing's part is `1/height`: as a wing collapses onto its
/// hinge the angle loses its meaning and the exact force grows without bound (up to
/// `|e|·10¹²` before [`hinge_angle`] calls the hinge degenerate). Scaling all four points'
/// parts alike keeps the forces summing to zero and free of torque; the force is then no
/// longer exactly the energy's gradient, for such slivers only.
fn wing_limit<R: Real>(edge: R::V3, grad: &[R::V3; 4]) -> R {
    let largest = grad[2].length().max(grad[3].length());
    let cap = R::ONE / (R::of_f32(MIN_WING) * edge.length());
    if largest > cap { cap / largest } else { R::ONE }
}

/// `theta − rest` wrapped into (−π, π]: a hinge folded through ±π stays continuous.
fn angle_difference<R: Real>(theta: R, rest: f32) -> R {
    let (pi, tau) = (
        R::of_f32(std::f32::consts::PI),
        R::of_f32(std::f32::consts::TAU),
    );
    let mut d = theta - R::of_f32(rest);
    if d > pi {
        d -= tau;
    } else if d < -pi {
        d += tau;
    }
    d
}

impl DihedralBending {
    /// Hinges of `model` with rest angles and weights from its rest positions, and
    /// stiffness `k` (N·m).
    pub fn new(model: &ClothModel, stiffness: f32) -> Self {
        let p = &model.rest_positions;
        let (mut rest, mut weight) = (Vec::new(), Vec::new());
        for h in &model.hinges {
            let [x0, x1, a, b] = h.map(|i| p[i as usize]);
            let e = x1 - x0;
            let areas = 0.5 * (e.cross(a - x0).length() + e.cross(b - x0).length());
            rest.push(hinge_angle::<f32>(x0, x1, a, b).map_or(0.0, |(t, _)| t));
            weight.push(if areas > 0.0 {
                3.0 * e.length_squared() / areas
            } else {
                0.0
            });
        }
        Self {
            stiffness,
            rest,
            weight,
        }
    }

    pub fn stiffness(&self) -> f32 {
        self.stiffness
    }

    /// Each hinge's rest angle (radians) and weight `3|e|²/(A₁ + A₂)`, in the model's order.
    pub fn rest_and_weight(&self) -> (&[f32], &[f32]) {
        (&self.rest, &self.weight)
    }

    pub fn set_stiffness(&mut self, stiffness: f32) {
        self.stiffness = stiffness;
    }

    /// Bending energy `Σ k·w·(θ − θ₀)²`, joules.
    pub fn potential_energy<R: Real>(&self, model: &ClothModel, pos: &[R::V3]) -> f64 {
        model
            .hinges
            .iter()
            .zip(self.rest.iter().zip(&self.weight))
            .filter_map(|(h, (&rest, &w))| {
                let [x0, x1, a, b] = h.map(|i| pos[i as usize]);
                hinge_angle::<R>(x0, x1, a, b).map(|(t, _)| {
                    let d = angle_difference(t, rest).to_f64();
                    (self.stiffness * w) as f64 * d * d
                })
            })
            .sum()
    }

    /// Adds `−∂E/∂x = −2k·w·(θ − θ₀)·∂θ/∂x` (N) to `f`, limited for a wing nearly collapsed
    /// onto its hinge (see `wing_limit`).
    /// In `f32` eight hinges at a time (`dihedral/lanes.rs`).
    pub fn add_forces<R: Real>(&self, model: &ClothModel, pos: &[R::V3], f: &mut [R::V3]) {
        if let Some(pos) = R::f32_slice(pos)
            && let Some(f) = R::f32_slice_mut(f)
        {
            // On the calling thread: shared with the team like the wind's, the hinges took
            // as long on two threads as on one (docs/performance.md, "The flag's hinges and
            // wind").
            let (rest, weight) = (&self.rest[..], &self.weight[..]);
            let k = [self.stiffness, MIN_WING];
            return lanes::add_forces(&model.hinges, [rest, weight], k, pos, f);
        }
        self.add_forces_one_by_one::<R>(model, pos, f);
    }

    /// [`DihedralBending::add_forces`] a hinge at a time, in either precision.
    fn add_forces_one_by_one<R: Real>(&self, model: &ClothModel, pos: &[R::V3], f: &mut [R::V3]) {
        for (h, (&rest, &w)) in model.hinges.iter().zip(self.rest.iter().zip(&self.weight)) {
            let [x0, x1, a, b] = h.map(|i| pos[i as usize]);
            let Some((theta, grad)) = hinge_angle::<R>(x0, x1, a, b) else {
                continue;
            };
            let scale = R::of_f32(-2.0 * self.stiffness * w)
                * angle_difference(theta, rest)
                * wing_limit::<R>(x1 - x0, &grad);
            for (&i, g) in h.iter().zip(grad) {
                f[i as usize] += g * scale;
            }
        }
    }
}

impl<R: Real> ForceTerm<R> for DihedralBending {
    fn add_forces(
        &self,
        model: &ClothModel,
        pos: &[R::V3],
        _vel: &[R::V3],
        _t: f64,
        f: &mut [R::V3],
    ) {
        DihedralBending::add_forces::<R>(self, model, pos, f);
    }

    fn potential_energy(&self, model: &ClothModel, pos: &[R::V3]) -> f64 {
        DihedralBending::potential_energy::<R>(self, model, pos)
    }
}
