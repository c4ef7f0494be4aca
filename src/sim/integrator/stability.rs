//! How long a substep each integrator can take on a vibration: every method applied to the
//! damped oscillator `x'' = −ω²x − γx'`, whose one-step map is a 2×2 matrix; the step is
//! stable while that matrix's spectral radius keeps the amplitude from growing.

use super::kind::IntegratorKind;

/// Growth the analysis still calls stable, per second of simulated time (1/s): an amplitude
/// that grows by at most 1 % a second is held by any damping the scene has.
const TOLERATED_GROWTH: f64 = 0.01;

impl IntegratorKind {
    /// The longest stable substep (s) for a vibration of angular frequency `omega` (rad/s)
    /// damped at rate `gamma` (1/s); `None` where every step is stable (implicit Euler, XPBD, VBD),
    /// `Some(0.0)` where no step is (explicit Euler on an undamped spring).
    pub fn stable_substep(self, omega: f64, gamma: f64) -> Option<f64> {
        match self {
            IntegratorKind::ImplicitEuler | IntegratorKind::Xpbd | IntegratorKind::Vbd => {
                return None;
            }
            IntegratorKind::ExplicitEuler
            | IntegratorKind::SemiImplicitEuler
            | IntegratorKind::Verlet
            | IntegratorKind::Rk2
            | IntegratorKind::Rk4 => {}
        }
        if !(omega.is_finite() && omega > 0.0 && gamma.is_finite()) {
            return Some(f64::INFINITY);
        }
        let stable = |h: f64| self.spectral_radius(omega, gamma, h).ln() <= TOLERATED_GROWTH * h;
        // Every method here is unstable beyond ωh = 3; walk down to a stable step, then
        // bisect between it and the unstable one above.
        let mut unstable = 3.0 / omega;
        let mut ok = unstable / 2.0;
        while !stable(ok) {
            unstable = ok;
            ok /= 2.0;
            if ok < 1e-12 / omega {
                return Some(0.0);
            }
        }
        for _ in 0..60 {
            let mid = 0.5 * (ok + unstable);
            if stable(mid) {
                ok = mid;
            } else {
                unstable = mid;
            }
        }
        Some(ok)
    }

    /// Whether every step, however short, grows an undamped vibration (explicit Euler and
    /// midpoint RK2: their one-step maps' spectral radii are `√(1 + (ωh)²)` and
    /// `√(1 + (ωh)⁴/4)`). A blow-up under them can be as slow as the step makes it, so one
    /// frame cannot tell it from motion the step resolves: the guard never admits a limit
    /// crossed under them ([`crate::sim::GuardLimits::admitting`]).
    pub fn gains_energy(self) -> bool {
        matches!(self, IntegratorKind::ExplicitEuler | IntegratorKind::Rk2)
    }

    /// Spectral radius of one step of `h` seconds on the damped oscillator.
    fn spectral_radius(self, omega: f64, gamma: f64, h: f64) -> f64 {
        let (x1, v1) = self.step_oscillator(omega, gamma, h, 1.0, 0.0);
        let (x2, v2) = self.step_oscillator(omega, gamma, h, 0.0, 1.0);
        let (trace, det) = (x1 + v2, x1 * v2 - x2 * v1);
        let disc = trace * trace - 4.0 * det;
        if disc < 0.0 {
            det.abs().sqrt()
        } else {
            let root = disc.sqrt();
            0.5 * (trace.abs() + root)
        }
    }

    /// One step of this integrator, as its file takes it, on `x'' = −ω²x − γx'` from `(x, v)`.
    fn step_oscillator(self, omega: f64, gamma: f64, h: f64, x: f64, v: f64) -> (f64, f64) {
        let a = |x: f64, v: f64| -omega * omega * x - gamma * v;
        match self {
            IntegratorKind::ExplicitEuler => (x + h * v, v + h * a(x, v)),
            IntegratorKind::SemiImplicitEuler => {
                let v1 = v + h * a(x, v);
                (x + h * v1, v1)
            }
            IntegratorKind::Verlet => {
                let a0 = a(x, v);
                let x1 = x + h * v + 0.5 * h * h * a0;
                let a1 = a(x1, v + h * a0);
                (x1, v + 0.5 * h * (a0 + a1))
            }
            IntegratorKind::Rk2 => {
                let (xm, vm) = (x + 0.5 * h * v, v + 0.5 * h * a(x, v));
                (x + h * vm, v + h * a(xm, vm))
            }
            IntegratorKind::Rk4 => {
                let f = |x: f64, v: f64| (v, a(x, v));
                let k1 = f(x, v);
                let k2 = f(x + 0.5 * h * k1.0, v + 0.5 * h * k1.1);
                let k3 = f(x + 0.5 * h * k2.0, v + 0.5 * h * k2.1);
                let k4 = f(x + h * k3.0, v + h * k3.1);
                (
                    x + h / 6.0 * (k1.0 + 2.0 * k2.0 + 2.0 * k3.0 + k4.0),
                    v + h / 6.0 * (k1.1 + 2.0 * k2.1 + 2.0 * k3.1 + k4.1),
                )
            }
            // Stable at any step; never asked (see `stable_substep`).
            IntegratorKind::ImplicitEuler | IntegratorKind::Xpbd | IntegratorKind::Vbd => (x, v),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The textbook limits on an undamped oscillator: symplectic Euler and Verlet ωh < 2,
    /// RK4 ωh < 2√2; explicit Euler has no stable step.
    #[test]
    fn the_undamped_limits_are_the_textbook_ones() {
        let omega = 1000.0;
        let limit = |kind: IntegratorKind| kind.stable_substep(omega, 0.0).unwrap() * omega;
        assert!((limit(IntegratorKind::SemiImplicitEuler) - 2.0).abs() < 1e-3);
        assert!((limit(IntegratorKind::Verlet) - 2.0).abs() < 1e-3);
        assert!((limit(IntegratorKind::Rk4) - 8f64.sqrt()).abs() < 1e-2);
        // Growth |1 + iωh| − 1 ≈ (ωh)²/2 a step: within 1 %/s only for ωh ≈ 1e-5.
        assert!(limit(IntegratorKind::ExplicitEuler) < 1e-4);
        assert!(
            limit(IntegratorKind::Rk2) < 0.1,
            "{}",
            limit(IntegratorKind::Rk2)
        );
        assert_eq!(
            IntegratorKind::ImplicitEuler.stable_substep(omega, 0.0),
            None
        );
        assert_eq!(IntegratorKind::Xpbd.stable_substep(omega, 0.0), None);
    }

    /// The methods said to gain energy are those whose step grows an undamped vibration at
    /// every step length tried, and the others' never does (symplectic Euler and Verlet keep
    /// it, RK4 damps it; implicit Euler, XPBD and VBD are not analysed here: stable).
    #[test]
    fn the_methods_that_gain_energy_grow_a_vibration_at_every_step() {
        let omega = 1000.0;
        for kind in IntegratorKind::ALL {
            let grows = [0.01, 0.1, 0.5, 1.0, 1.5]
                .map(|wh| kind.spectral_radius(omega, 0.0, wh / omega) > 1.0 + 1e-12);
            let expected = [kind.gains_energy(); 5];
            assert_eq!(grows, expected, "{kind}");
        }
    }

    /// Damping makes explicit Euler stable below `h = γ/ω²`: for `λ = −γ/2 ± i√(ω² − γ²/4)`,
    /// `|1 + hλ|² = 1 − hγ + h²ω²`.
    #[test]
    fn damping_gives_explicit_euler_its_textbook_step() {
        let (omega, gamma) = (1000.0f64, 200.0f64);
        let h = IntegratorKind::ExplicitEuler
            .stable_substep(omega, gamma)
            .unwrap();
        let expected = gamma / (omega * omega);
        assert!((h / expected - 1.0).abs() < 0.02, "{h} vs {expected}");
    }
}
