//! The optional effects: dihedral bending, bend springs, wind, self-collision, and proof
//! that a scene runs only the effects it lists.

use std::path::Path;

use clothsim::cloth::{ClothModel, ClothState};
use clothsim::mesh::{GridOrientation, GridSpec};
use clothsim::scene::{Scene, SceneFile, Simulation};
use clothsim::sim::forces::{DihedralBending, hinge_angle};
use clothsim::sim::{
    BendingModel, ContactError, Effect, ForceTerm, SELF_SETUP, SelfCollision, SelfContacts, Wind,
    WindForce,
};
use glam::{Quat, Vec3};

/// Deterministic pseudo-random numbers in [−1, 1].
struct Lcg(u64);

impl Lcg {
    fn next(&mut self) -> f32 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((self.0 >> 40) as f32 / (1u64 << 24) as f32) * 2.0 - 1.0
    }

    fn vec(&mut self) -> Vec3 {
        Vec3::new(self.next(), self.next(), self.next())
    }
}

fn grid_model(quads: u32, size: f32) -> ClothModel {
    let mesh = GridSpec::square(quads, size, GridOrientation::Horizontal, Vec3::ZERO)
        .build()
        .unwrap();
    ClothModel::new(&mesh, 0.2, &[])
}

fn forces_of(b: &DihedralBending, model: &ClothModel, pos: &[Vec3]) -> Vec<Vec3> {
    let mut f = vec![Vec3::ZERO; pos.len()];
    b.add_forces::<f32>(model, pos, &mut f);
    f
}

// ---------------------------------------------------------------- dihedral bending

#[test]
fn the_hinge_angle_gradient_matches_finite_differences() {
    let mut rng = Lcg(7);
    let eps = 1e-3;
    let mut worst = 0.0f32;
    for _ in 0..200 {
        // A hinge folded anywhere between flat and nearly shut.
        let x0 = Vec3::ZERO + 0.1 * rng.vec();
        let x1 = Vec3::X + 0.1 * rng.vec();
        let a = Vec3::new(0.4, 0.0, 0.8) + 0.2 * rng.vec();
        let fold = Quat::from_rotation_x(2.5 * rng.next());
        let b = fold * Vec3::new(0.6, 0.0, -0.8) + 0.2 * rng.vec();
        let mut p = [x0, x1, a, b];
        let (_, grad) = hinge_angle::<f32>(p[0], p[1], p[2], p[3]).unwrap();
        for i in 0..4 {
            for axis in 0..3 {
                let keep = p[i];
                p[i][axis] = keep[axis] + eps;
                let up = hinge_angle::<f32>(p[0], p[1], p[2], p[3]).unwrap().0;
                p[i][axis] = keep[axis] - eps;
                let down = hinge_angle::<f32>(p[0], p[1], p[2], p[3]).unwrap().0;
                p[i] = keep;
                let fd = (up - down) / (2.0 * eps);
                worst = worst.max((fd - grad[i][axis]).abs() / grad[i].length().max(1.0));
            }
        }
    }
    // f32 central differences are good to about 1e-4 here; a wrong sign, a missing term or
    // a swapped wing is off by order one.
    assert!(worst < 2e-3, "worst relative gradient error {worst}");
}

#[test]
fn dihedral_forces_are_minus_the_energy_gradient() {
    let model = grid_model(3, 1.0);
    let bending = DihedralBending::new(&model, 0.05);
    let mut rng = Lcg(11);
    let mut pos = model.rest_positions.clone();
    for p in &mut pos {
        p.y += 0.08 * rng.next();
    }
    let f = forces_of(&bending, &model, &pos);
    let eps = 1e-3;
    let scale = f.iter().map(|v| v.length()).fold(0.0f32, f32::max);
    assert!(scale > 1e-3, "the bent sheet has bending forces");
    for i in 0..pos.len() {
        for axis in 0..3 {
            let keep = pos[i];
            pos[i][axis] = keep[axis] + eps;
            let up = bending.potential_energy::<f32>(&model, &pos);
            pos[i][axis] = keep[axis] - eps;
            let down = bending.potential_energy::<f32>(&model, &pos);
            pos[i] = keep;
            let fd = -((up - down) / (2.0 * eps as f64)) as f32;
            assert!(
                (fd - f[i][axis]).abs() < 2e-3 * scale,
                "particle {i} axis {axis}: force {} vs −dE/dx {fd}",
                f[i][axis]
            );
        }
    }
}

/// One quad of a 1 m grid: two triangles and one hinge, its diagonal, flat at rest; its
/// dihedral bending of `stiffness`, and the hinge's points (edge ends, then wings).
fn one_hinge(stiffness: f32) -> (ClothModel, DihedralBending, [usize; 4]) {
    let model = grid_model(1, 1.0);
    assert_eq!(model.hinges.len(), 1);
    let bending = DihedralBending::new(&model, stiffness);
    let hinge = model.hinges[0].map(|i| i as usize);
    (model, bending, hinge)
}

#[test]
fn a_wing_collapsed_onto_its_hinge_gets_a_bounded_force_with_no_net_force_or_torque() {
    let (model, bending, [x0, x1, a, b]) = one_hinge(0.05);
    let rest = &model.rest_positions;
    let e = rest[x1] - rest[x0];
    let normal = e.cross(rest[b] - rest[x0]).normalize();
    // Wing `a` folded to 90° and pressed down towards the hinge's middle: its apex
    // `height × |e|` above the hinge, so the angle stays 90° whatever the height.
    let folded = |height: f32| {
        let mut pos = rest.clone();
        pos[a] = rest[x0] + 0.5 * e + height * e.length() * normal;
        let f = forces_of(&bending, &model, &pos);
        (pos, f)
    };
    let largest = |f: &[Vec3]| f.iter().map(|v| v.length()).fold(0.0f32, f32::max);
    // At 2 % of the hinge the exact force applies; lower, it would grow as 1/height
    // (20 000 times larger at 10⁻⁶). It stays at the 2 % level instead.
    let (_, at_limit) = folded(0.02);
    let (pos, f) = folded(1e-6);
    let (limit, sliver) = (largest(&at_limit), largest(&f));
    assert!(limit > 0.0);
    assert!(
        (0.5 * limit..=1.01 * limit).contains(&sliver),
        "a sliver's force {sliver} N, at the limit {limit} N"
    );
    // Limited alike at all four points: still no net force and no torque.
    let net: Vec3 = f.iter().sum();
    let torque: Vec3 = pos
        .iter()
        .zip(&f)
        .map(|(x, f)| (*x - rest[x0]).cross(*f))
        .sum();
    assert!(net.length() < 1e-5 * sliver, "net force {net}");
    assert!(
        torque.length() < 1e-5 * sliver * e.length(),
        "torque {torque}"
    );
}

#[test]
fn a_flat_sheet_has_no_bending_force_however_it_is_placed() {
    let model = grid_model(4, 1.0);
    let bending = DihedralBending::new(&model, 1.0);
    let turn = Quat::from_euler(glam::EulerRot::XYZ, 0.7, -1.1, 0.4);
    let moved: Vec<Vec3> = model
        .rest_positions
        .iter()
        .map(|&p| turn * p + Vec3::new(3.0, -2.0, 1.0))
        .collect();
    let largest = |pos: &[Vec3]| {
        forces_of(&bending, &model, pos)
            .iter()
            .map(|f| f.length())
            .fold(0.0f32, f32::max)
    };
    // The scale: one hinge folded by a single degree.
    let [x0, x1, _, b] = model.hinges[0].map(|i| i as usize);
    let mut one_degree = model.rest_positions.clone();
    let axis = (one_degree[x1] - one_degree[x0]).normalize();
    one_degree[b] = one_degree[x0]
        + Quat::from_axis_angle(axis, 1f32.to_radians()) * (one_degree[b] - one_degree[x0]);
    let scale = largest(&one_degree);
    assert_eq!(
        largest(&model.rest_positions),
        0.0,
        "exactly flat, exactly no force"
    );
    // Moved and turned, the sheet is flat to f32 rounding: a thousandth of a degree's force.
    let worst = largest(&moved);
    assert!(
        worst < 1e-3 * scale,
        "a flat sheet feels {worst} N ({scale} N per degree)"
    );
    assert!(bending.potential_energy::<f32>(&model, &moved) < 1e-9);
}

#[test]
fn the_bending_force_points_back_towards_the_rest_angle() {
    // One hinge: two triangles sharing the edge x0–x1 along x; wing b folded up by 40°.
    let (model, bending, [x0, x1, a, b]) = one_hinge(0.1);
    let mut pos = model.rest_positions.clone();
    let axis = (pos[x1] - pos[x0]).normalize();
    let fold = Quat::from_axis_angle(axis, 40f32.to_radians());
    pos[b] = pos[x0] + fold * (pos[b] - pos[x0]);
    let f = forces_of(&bending, &model, &pos);
    // Wing b is pushed back down towards where it rests, and the energy falls along the force.
    let back = model.rest_positions[b] - pos[b];
    assert!(f[b].dot(back) > 0.0, "force {} on the lifted wing", f[b]);
    assert!(
        f[a].dot(f[b]) > 0.0,
        "both wings move the same way relative to the edge"
    );
    let e0 = bending.potential_energy::<f32>(&model, &pos);
    let step: Vec<Vec3> = pos.iter().zip(&f).map(|(p, f)| *p + 1e-3 * *f).collect();
    assert!(bending.potential_energy::<f32>(&model, &step) < e0);
    // Momentum: the forces are internal.
    let total: Vec3 = f.iter().sum();
    assert!(total.length() < 1e-5 * f[b].length(), "net force {total}");
}

/// A 8×1-quad strip, 1 m × 0.125 m, folded 90° about its middle, weightless, with `bending`.
fn folded_strip(bending: Option<&str>) -> Simulation {
    let bending = bending.map_or(String::new(), |b| {
        format!("[[effects]]\ntype = \"bending\"\n{b}\n")
    });
    let text = format!(
        "name = \"strip\"\n\
         [cloth]\ngrid = {{ quads = [8, 1], size = [1.0, 0.125] }}\n\
         [material]\ndensity = 0.2\n\
         stiffness = {{ structural = 200.0, shear = 50.0, bend = 5.0 }}\n\
         damping = {{ structural = 0.01, shear = 0.01, bend = 0.001 }}\n\
         [[effects]]\ntype = \"air-damping\"\nrate = 1.0\n{bending}"
    );
    let file = SceneFile::parse(&text, Path::new("strip.toml")).unwrap();
    let mut sim = Simulation::new(Scene::from_file(file, None).unwrap());
    sim.modify_state(|s| {
        for p in &mut s.pos {
            if p.x > 0.0 {
                *p = Vec3::new(0.0, p.x, p.z);
            }
        }
    });
    sim
}

/// The angle between the strip's two halves' directions, degrees (0 flat).
fn fold_angle(sim: &Simulation) -> f32 {
    let pos = &sim.state().pos;
    let x0 = &sim.model().rest_positions;
    let mean = |pick: &dyn Fn(f32) -> bool| -> Vec3 {
        let (sum, n) = pos
            .iter()
            .zip(x0)
            .filter(|(_, r)| pick(r.x))
            .fold((Vec3::ZERO, 0.0), |(s, n), (p, _)| (s + *p, n + 1.0));
        sum / n
    };
    let left = mean(&|x| x < -0.49);
    let middle = mean(&|x| x.abs() < 0.01);
    let right = mean(&|x| x > 0.49);
    (middle - left).angle_between(right - middle).to_degrees()
}

#[test]
fn a_folded_strip_returns_towards_flat_with_either_bending_model() {
    for model in [
        Some("model = \"dihedral\"\nstiffness = 0.005"),
        Some("model = \"springs\""),
        None,
    ] {
        let mut sim = folded_strip(model);
        let start = fold_angle(&sim);
        assert!((start - 90.0).abs() < 0.1, "folded to {start}°");
        // Sampled every frame for 3 s: how close to flat it comes, and where it ends.
        let mut closest = start;
        for _ in 0..180 {
            sim.step_frame().expect("stable");
            closest = closest.min(fold_angle(&sim));
        }
        let end = fold_angle(&sim);
        match model {
            // Bend springs are less damped here and swing through flat; both come back.
            Some(m) => assert!(
                closest < 10.0 && end < 45.0,
                "{m}: came within {closest}° of flat, ended at {end}°"
            ),
            // Springs along the strip and across it do not resist folding at all.
            None => assert!(closest > 85.0, "without bending the fold stays: {closest}°"),
        }
    }
}

// ---------------------------------------------------------------- wind

/// A 1 m² square plate of two triangles facing `normal`, moving at `vel`.
fn plate(normal: Vec3, vel: Vec3) -> (ClothModel, Vec<Vec3>, Vec<Vec3>) {
    let model = grid_model(1, 1.0);
    // The grid lies in x–z with normal ±y; turn it to face `normal`.
    let turn = Quat::from_rotation_arc(Vec3::Y, normal.normalize());
    let pos: Vec<Vec3> = model.rest_positions.iter().map(|&p| turn * p).collect();
    let vel = vec![vel; pos.len()];
    (model, pos, vel)
}

fn wind_force(wind: &Wind, normal: Vec3, vel: Vec3) -> Vec3 {
    let (model, pos, vel) = plate(normal, vel);
    let mut f = vec![Vec3::ZERO; pos.len()];
    ForceTerm::<f32>::add_forces(
        &WindForce::new(*wind, &model),
        &model,
        &pos,
        &vel,
        0.0,
        &mut f,
    );
    f.iter().sum()
}

fn steady(velocity: Vec3) -> Wind {
    Wind {
        velocity,
        gust: 0.0,
        ..Wind::default()
    }
}

#[test]
fn wind_pushes_a_plate_facing_it_with_its_dynamic_pressure() {
    let wind = steady(Vec3::new(4.0, 0.0, 0.0));
    let f = wind_force(&wind, Vec3::X, Vec3::ZERO);
    // ½ρ C_d A v² = 0.5 · 1.2 · 1 · 1 m² · 16 = 9.6 N, downwind; no lift head-on.
    assert!((f - Vec3::new(9.6, 0.0, 0.0)).length() < 1e-4, "{f}");
    // The plate's side does not matter.
    let back = wind_force(&wind, -Vec3::X, Vec3::ZERO);
    assert!((back - f).length() < 1e-4, "{back}");
    // Edge-on it feels nothing.
    let edge = wind_force(&wind, Vec3::Y, Vec3::ZERO);
    assert!(edge.length() < 1e-5, "{edge}");
}

#[test]
fn a_cloth_moving_with_the_air_feels_no_wind() {
    let velocity = Vec3::new(3.0, 0.5, -2.0);
    let wind = steady(velocity);
    let tilted = Vec3::new(1.0, 1.0, 0.3);
    assert_eq!(wind_force(&wind, tilted, velocity), Vec3::ZERO);
    // Moving at the wind speed the other way doubles the relative speed: four times the force.
    let still = wind_force(&wind, tilted, Vec3::ZERO);
    let against = wind_force(&wind, tilted, -velocity);
    assert!(
        (against - 4.0 * still).length() < 1e-3 * against.length(),
        "{still} {against}"
    );
}

#[test]
fn a_tilted_plate_gets_lift_across_the_flow() {
    let wind = Wind {
        drag: 0.0,
        ..steady(Vec3::new(5.0, 0.0, 0.0))
    };
    // Tilted 45° between the flow (x) and up (y).
    let f = wind_force(&wind, Vec3::new(1.0, 1.0, 0.0), Vec3::ZERO);
    // ½ρ C_l A v² cos45° sin45° = 0.5 · 1.2 · 0.6 · 25 · 0.5 = 4.5 N, across the flow.
    assert!(f.x.abs() < 1e-4, "lift has no part along the flow: {f}");
    assert!((f.length() - 4.5).abs() < 1e-3, "{f}");
    // The flow meets the plate's underside, which faces into it: lifted up. Tilted the
    // other way, the same plate is pushed down.
    assert!(f.y > 1.0, "{f}");
    let down = wind_force(&wind, Vec3::new(1.0, -1.0, 0.0), Vec3::ZERO);
    assert!((down.y + f.y).abs() < 1e-4, "{f} {down}");
}

#[test]
fn gusts_vary_the_wind_in_time_and_travel_with_it() {
    let wind = Wind::default();
    let at = |x: f32, t: f64| wind.air_velocity::<f32>(Vec3::new(x, 0.0, 0.0), t);
    let samples: Vec<f32> = (0..100)
        .map(|i| at(0.0, i as f64 * 0.05).length())
        .collect();
    let (lo, hi) = samples
        .iter()
        .fold((f32::INFINITY, 0.0f32), |(l, h), &s| (l.min(s), h.max(s)));
    assert!(
        hi - lo > 0.5 * wind.speed() * wind.gust,
        "gusts: {lo}..{hi} m/s"
    );
    assert!(hi <= wind.peak_speed() + 1e-4);
    // Frozen in the flow: what passes x = 0 at t passes x = 2 m at t + 2/speed.
    let later = 2.0 / wind.speed() as f64;
    assert!((at(0.0, 0.3) - at(2.0, 0.3 + later)).length() < 1e-3);
}

/// Mean x of the flag's free particles, and the mean z of its free edge, over a run.
fn flag_run(wind: Option<Vec3>, seconds: f64) -> (Vec<f32>, Vec<f32>) {
    let mut sim = Simulation::new(Scene::builtin("flag").unwrap());
    let mut effects = sim.effects().to_vec();
    match wind {
        Some(v) => {
            for e in &mut effects {
                if let Effect::Wind(w) = e {
                    w.velocity = v;
                }
            }
        }
        None => effects.retain(|e| !matches!(e, Effect::Wind(_))),
    }
    sim.set_effects(effects).unwrap();
    let rest = sim.model().rest_positions.clone();
    let right = rest.iter().map(|p| p.x).fold(f32::MIN, f32::max);
    let free_edge: Vec<usize> = (0..rest.len())
        .filter(|&i| rest[i].x > right - 1e-4)
        .collect();
    let frames = (seconds / sim.params().step.dt as f64).round() as usize;
    let (mut mean_x, mut edge_z) = (Vec::new(), Vec::new());
    for _ in 0..frames {
        sim.step_frame().expect("the flag is stable");
        let pos = &sim.state().pos;
        mean_x.push(pos.iter().map(|p| p.x).sum::<f32>() / pos.len() as f32);
        edge_z.push(free_edge.iter().map(|&i| pos[i].z).sum::<f32>() / free_edge.len() as f32);
    }
    (mean_x, edge_z)
}

fn mean(v: &[f32]) -> f32 {
    v.iter().sum::<f32>() / v.len() as f32
}

fn spread(v: &[f32]) -> f32 {
    let m = mean(v);
    (v.iter().map(|x| (x - m) * (x - m)).sum::<f32>() / v.len() as f32).sqrt()
}

#[test]
fn the_flag_streams_downwind_and_keeps_flapping() {
    // 60 frames a second: [1 s, 2.5 s) early, [3.5 s, 5 s) late.
    let (early, late) = (60..150, 210..300);
    let (x, z) = flag_run(Some(Vec3::new(6.0, 0.0, 0.0)), 5.0);
    let (x_back, _) = flag_run(Some(Vec3::new(-6.0, 0.0, 0.0)), 5.0);
    let (_, z_calm) = flag_run(None, 5.0);
    // The pole is at x = −0.75; the flag starts spread out to +0.75 (mean x 0).
    let streaming = mean(&x[late.clone()]);
    let against = mean(&x_back[late.clone()]);
    assert!(
        streaming > -0.3,
        "the flag streams out downwind: mean x {streaming}"
    );
    assert!(
        against < -1.0,
        "wind from −x blows it out past the pole: {against}"
    );
    // Flapping: the free edge keeps moving across the wind late in the run as much as early.
    let (flap_early, flap_late) = (spread(&z[early]), spread(&z[late.clone()]));
    assert!(
        flap_late > 0.02,
        "the free edge sways by {flap_late} m late"
    );
    assert!(
        flap_late > 0.3 * flap_early,
        "flapping dies out: {flap_early} → {flap_late}"
    );
    // In still air it hangs in its own plane: the sway is the wind's doing.
    assert!(spread(&z_calm[late]) < 0.01 * flap_late);
}

// ---------------------------------------------------------------- self-collision

/// Whether point `x` moving from `x0` to `x1` passes through the triangle moving from
/// `t0` to `t1` during the substep (all linear in time).
fn crosses(x0: Vec3, x1: Vec3, t0: [Vec3; 3], t1: [Vec3; 3]) -> bool {
    let at = |s: f32| {
        let x = x0.lerp(x1, s);
        let [a, b, c] = [0, 1, 2].map(|k| t0[k].lerp(t1[k], s));
        ((x - a).dot((b - a).cross(c - a)), x, [a, b, c])
    };
    let (d0, d1) = (at(0.0).0, at(1.0).0);
    if d0 * d1 >= 0.0 {
        return false;
    }
    // Bisect to the moment the point is in the triangle's plane.
    let (mut lo, mut hi) = (0.0f32, 1.0f32);
    for _ in 0..40 {
        let mid = 0.5 * (lo + hi);
        if at(mid).0 * d0 > 0.0 {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    let (_, x, [a, b, c]) = at(0.5 * (lo + hi));
    // Inside the triangle then (barycentric weights all positive, with a margin).
    let n = (b - a).cross(c - a);
    let n2 = n.length_squared();
    if n2 <= 0.0 {
        return false;
    }
    let w = [
        (c - b).cross(x - b).dot(n) / n2,
        (a - c).cross(x - c).dot(n) / n2,
        (b - a).cross(x - a).dot(n) / n2,
    ];
    w.iter().all(|&w| w > 1e-3)
}

/// Crossings during one substep from `before` to `after`. A particle can only cross a
/// triangle whose swept box its own swept box meets: both are binned into cells of `cell`.
fn crossings(model: &ClothModel, before: &[Vec3], after: &[Vec3], cell: f32) -> usize {
    let cell_of = |p: Vec3| (p / cell).floor().as_ivec3();
    let key = |c: glam::IVec3| {
        ((c.x as i64 & 0xFFFFF) << 40) | ((c.y as i64 & 0xFFFFF) << 20) | (c.z as i64 & 0xFFFFF)
    };
    let boxed = |points: &[Vec3]| {
        let lo = points.iter().fold(Vec3::MAX, |m, p| m.min(*p));
        let hi = points.iter().fold(Vec3::MIN, |m, p| m.max(*p));
        (cell_of(lo), cell_of(hi))
    };
    let mut bins: Vec<(i64, u32)> = Vec::with_capacity(before.len());
    for (i, (p0, p1)) in before.iter().zip(after).enumerate() {
        let (lo, hi) = boxed(&[*p0, *p1]);
        for x in lo.x..=hi.x {
            for y in lo.y..=hi.y {
                for z in lo.z..=hi.z {
                    bins.push((key(glam::IVec3::new(x, y, z)), i as u32));
                }
            }
        }
    }
    bins.sort_unstable();
    let mut pairs = Vec::new();
    for (t, tri) in model.triangles.iter().enumerate() {
        let t0 = tri.map(|i| before[i as usize]);
        let t1 = tri.map(|i| after[i as usize]);
        let (lo, hi) = boxed(&[t0[0], t0[1], t0[2], t1[0], t1[1], t1[2]]);
        for x in lo.x..=hi.x {
            for y in lo.y..=hi.y {
                for z in lo.z..=hi.z {
                    let k = key(glam::IVec3::new(x, y, z));
                    let first = bins.partition_point(|&(b, _)| b < k);
                    for &(_, p) in bins[first..].iter().take_while(|&&(b, _)| b == k) {
                        if !tri.contains(&p) {
                            pairs.push((p, t as u32));
                        }
                    }
                }
            }
        }
    }
    // A pair met in several cells is checked once.
    pairs.sort_unstable();
    pairs.dedup();
    pairs
        .into_iter()
        .filter(|&(p, t)| {
            let tri = model.triangles[t as usize];
            let p = p as usize;
            crosses(
                before[p],
                after[p],
                tri.map(|i| before[i as usize]),
                tri.map(|i| after[i as usize]),
            )
        })
        .count()
}

/// Runs `self-fold` substep by substep for `seconds`, counting particles that pass through
/// a triangle; returns the count and the simulation.
fn self_fold(with_self_collision: bool, seconds: f64) -> (usize, Simulation) {
    let mut sim = Simulation::new(Scene::builtin("self-fold").unwrap());
    if !with_self_collision {
        let mut effects = sim.effects().to_vec();
        effects.retain(|e| !matches!(e, Effect::SelfCollision(_)));
        sim.set_effects(effects).unwrap();
    }
    let substeps = (seconds / sim.substep_length() as f64).round() as usize;
    let cell = 0.03;
    let mut found = 0;
    for _ in 0..substeps {
        let before = sim.state().pos.clone();
        sim.substep().expect("stable");
        found += crossings(sim.model(), &before, &sim.state().pos, cell);
    }
    (found, sim)
}

#[test]
fn self_fold_folds_onto_itself_without_passing_through() {
    // Folded and settled by 2.5 s (kinetic energy below 2e-4 J).
    let (found, sim) = self_fold(true, 3.0);
    let thickness = sim
        .effects()
        .iter()
        .find_map(|e| match e {
            Effect::SelfCollision(s) => Some(s.thickness),
            _ => None,
        })
        .unwrap();
    assert_eq!(found, 0, "particles passed through the cloth");
    // It did fold: many particles lie on top of another layer of cloth.
    let pos = &sim.state().pos;
    let above = pos
        .iter()
        .filter(|p| p.y > 3.0 * thickness + 0.1 * p.z.abs())
        .count();
    assert!(above > 60, "only {above} particles are on a second layer");
    // No two particles that share no triangle are closer than the thickness, less 10 %.
    let model = sim.model();
    let mut neighbours = vec![Vec::new(); pos.len()];
    for t in &model.triangles {
        for &a in t {
            neighbours[a as usize].extend_from_slice(t);
        }
    }
    let mut closest = f32::INFINITY;
    for i in 0..pos.len() {
        for j in i + 1..pos.len() {
            if !neighbours[i].contains(&(j as u32)) {
                closest = closest.min(pos[i].distance(pos[j]));
            }
        }
    }
    assert!(
        closest > 0.9 * thickness,
        "closest non-neighbours {closest} m, thickness {thickness} m"
    );
}

#[test]
fn without_self_collision_the_same_fold_passes_through_itself() {
    // The check above can fail: the same scene without the effect crosses itself as soon
    // as the falling half reaches the lower one (about 0.43 s).
    let (found, _) = self_fold(false, 0.6);
    assert!(found > 10, "{found} crossings");
}

/// One self-collision pass of `solver` with `params` moving `state` from where it is now
/// (its substep's start).
fn one_pass(
    solver: &mut SelfContacts,
    params: &SelfCollision,
    model: &ClothModel,
    state: &mut ClothState,
) -> Result<usize, ContactError> {
    let start = state.pos.clone();
    solver.resolve([params.thickness, params.friction], model, &start, state)
}

/// A square cloth of `quads`² quads folded in half: the back half lies over the front half
/// at 60 % of the thickness, so every particle of the upper layer is in contact.
fn folded_sheet(quads: u32, thickness: f32) -> (ClothModel, ClothState) {
    let model = grid_model(quads, 1.0);
    let mut state = ClothState::at_rest(&model);
    for p in &mut state.pos {
        if p.z < 0.0 {
            *p = Vec3::new(p.x, 0.6 * thickness, -p.z);
        }
    }
    (model, state)
}

#[test]
fn self_collision_work_grows_linearly_with_the_particle_count() {
    let mut per_particle = Vec::new();
    for quads in [16, 32, 64] {
        // A quarter of the spacing, as the app suggests.
        let params = SelfCollision {
            thickness: 0.25 / quads as f32,
            friction: 0.0,
        };
        let (model, mut state) = folded_sheet(quads, params.thickness);
        let mut solver = SelfContacts::default();
        one_pass(&mut solver, &params, &model, &mut state).unwrap();
        let n = model.particle_count() as f64;
        per_particle.push(solver.work.candidates as f64 / n);
        assert!(solver.work.contacts > 0);
    }
    // Four times the particles each time: an all-pairs search would do four times the work
    // per particle; the tree's search does about the same.
    for pair in per_particle.windows(2) {
        assert!(
            pair[1] < 1.3 * pair[0],
            "candidates per particle {per_particle:?}"
        );
    }
}

/// Particle–triangle pairs (not sharing a corner) closer than `gap`, by brute force.
fn close_pairs(model: &ClothModel, pos: &[Vec3], gap: f32) -> usize {
    let mut count = 0;
    for (p, x) in pos.iter().enumerate() {
        for t in &model.triangles {
            if !t.contains(&(p as u32)) {
                let [a, b, c] = t.map(|i| pos[i as usize]);
                if point_triangle_distance(*x, a, b, c) < gap {
                    count += 1;
                }
            }
        }
    }
    count
}

#[test]
fn the_broad_phase_misses_no_contact() {
    let params = SelfCollision {
        thickness: 0.02,
        friction: 0.0,
    };
    let (model, state) = folded_sheet(12, params.thickness);
    one_pass_separates_every_pair(&params, &model, state);
}

/// One pass separates every pair it finds to the thickness; a pair the broad phase missed
/// would still be at 60 % of it.
fn one_pass_separates_every_pair(
    params: &SelfCollision,
    model: &ClothModel,
    mut state: ClothState,
) {
    let before = close_pairs(model, &state.pos, params.thickness);
    assert!(before > 100, "{before} pairs in contact to start with");
    let mut solver = SelfContacts::default();
    one_pass(&mut solver, params, model, &mut state).unwrap();
    let left = close_pairs(model, &state.pos, 0.8 * params.thickness);
    assert_eq!(left, 0, "pairs still overlapping after one pass");
}

/// A folded sheet stretched along x by a factor growing from 1 to `stretch` across it, so
/// its triangles are of every size from the rest size up.
fn stretched_sheet(quads: u32, thickness: f32, stretch: f32) -> (ClothModel, ClothState) {
    let (model, mut state) = folded_sheet(quads, thickness);
    for p in &mut state.pos {
        let t = p.x + 0.5;
        p.x = t * (1.0 + (stretch - 1.0) * t);
    }
    (model, state)
}

#[test]
fn stretched_triangles_miss_no_contact() {
    let params = SelfCollision {
        thickness: 0.02,
        friction: 0.0,
    };
    let (model, state) = stretched_sheet(12, params.thickness, 200.0);
    one_pass_separates_every_pair(&params, &model, state);
}

/// Story: self-collision binned each triangle into every cell of its box; a cloth that blew
/// up within a frame had boxes billions of cells wide, and a 60 × 60 cloth aborted on an
/// 8 GB allocation. The tree the search walks is as large whatever the positions, and
/// the pairs it keeps follow how near the particles' paths come, not how far they spread:
/// flung farther, the folded sheet keeps fewer (9 944 with offsets up to 0.3 m, whose
/// paths cross, 5 026 up to 3 m, 54 up to 300 m, none up to 30 km); a non-finite
/// position, or a triangle a million cells wide, is refused.
#[test]
fn a_cloth_flung_farther_keeps_fewer_pairs() {
    let params = SelfCollision::default();
    let (model, rest) = folded_sheet(16, params.thickness);
    let mut solver = SelfContacts::default();
    let mut kept = Vec::new();
    // Each particle flung by a pseudo-random offset up to `reach` metres.
    for reach in [0.3f32, 3.0, 300.0, 3e4] {
        let mut state = rest.clone();
        for (i, p) in state.pos.iter_mut().enumerate() {
            // In [-1, 1], cubed: most particles move a little, a few far.
            let r = |k: u32| {
                let h = (i as u32).wrapping_mul(2654435761) ^ k.wrapping_mul(40503);
                let u = (h.wrapping_mul(2246822519) >> 8) as f32 / (1u32 << 24) as f32;
                (2.0 * u - 1.0).powi(3)
            };
            *p += reach * Vec3::new(r(1), r(2), r(3));
        }
        one_pass(&mut solver, &params, &model, &mut state).unwrap();
        kept.push(solver.work.candidates);
    }
    assert!(kept[0] > 1000, "{kept:?}");
    assert!(kept.windows(2).all(|w| w[1] < w[0]), "{kept:?}");
    assert!(kept[2] < 100 && kept[3] == 0, "{kept:?}");
    // Particle 7 sent to `y`: the pass refuses the state and moves nothing.
    let mut refused = |y: f32| {
        let mut state = rest.clone();
        state.pos[7].y = y;
        let bits = |pos: &[Vec3]| -> Vec<[u32; 3]> {
            pos.iter().map(|p| p.to_array().map(f32::to_bits)).collect()
        };
        let start = bits(&state.pos);
        let err = one_pass(&mut solver, &params, &model, &mut state).unwrap_err();
        assert_eq!(bits(&state.pos), start, "nothing moved");
        err
    };
    let err = refused(f32::NAN);
    assert_eq!(err, ContactError::NonFinite { particle: 7 });
    let err = refused(1e9);
    assert!(matches!(err, ContactError::Extent { .. }), "{err}");
    // Sent there over the substep from rest (the pairs judged by the motion, where the
    // triangles' boxes are not kept): refused too, nothing moved.
    let mut state = rest.clone();
    state.pos[7].y = 1e9;
    let end = state.pos.clone();
    let thickness = params.thickness;
    let err =
        (solver.resolve([thickness, params.friction], &model, &rest.pos, &mut state)).unwrap_err();
    // In the frame of the cloth's mean motion every particle moves by 1/289 of 10⁹ m:
    // the first triangle already spans more than a million cells.
    let ContactError::Extent {
        triangle, extent, ..
    } = err
    else {
        panic!("{err}");
    };
    assert_eq!(triangle, 0, "{err}");
    assert!((extent - 1e9 / 289.0).abs() < 1e3, "{err}");
    assert_eq!(state.pos, end, "nothing moved");
}

fn point_triangle_distance(p: Vec3, a: Vec3, b: Vec3, c: Vec3) -> f32 {
    // Dense sampling is enough for a test oracle at this scale.
    let mut best = f32::INFINITY;
    let n = 40;
    for i in 0..=n {
        for j in 0..=(n - i) {
            let (u, v) = (i as f32 / n as f32, j as f32 / n as f32);
            best = best.min(p.distance(a + u * (b - a) + v * (c - a)));
        }
    }
    best
}

// ---------------------------------------------------------------- only what is listed runs

fn phases_of(scene: &str, change: impl FnOnce(&mut Vec<Effect>)) -> Vec<String> {
    let mut sim = Simulation::new(Scene::builtin(scene).unwrap());
    let mut effects = sim.effects().to_vec();
    change(&mut effects);
    sim.set_effects(effects).unwrap();
    sim.run(0.1).phases.into_keys().collect()
}

#[test]
fn only_the_effects_a_scene_lists_appear_as_phases() {
    let hanging = phases_of("hanging", |_| {});
    for absent in [
        "sphere",
        "plane",
        "self-collision",
        "self-upkeep",
        "contact-start",
        "wind",
    ] {
        assert!(
            !hanging.iter().any(|p| p == absent),
            "{absent} in {hanging:?}"
        );
    }
    for present in ["springs", "gravity", "air-damping", "bending", "integrate"] {
        assert!(
            hanging.iter().any(|p| p == present),
            "{present} missing: {hanging:?}"
        );
    }
    let drop = phases_of("sphere-drop", |_| {});
    assert!(
        drop.contains(&"sphere".into()) && drop.contains(&"plane".into()),
        "{drop:?}"
    );
    // The contacts' start is kept wherever there are contacts; self-contact's upkeep
    // between the effects only with self-contact.
    assert!(drop.contains(&"contact-start".into()), "{drop:?}");
    assert!(!drop.contains(&"self-upkeep".into()), "{drop:?}");
    assert!(phases_of("flag", |_| {}).contains(&"wind".into()));
    assert!(phases_of("self-fold", |_| {}).contains(&"self-collision".into()));
    // Adding an effect adds its phase; removing one removes it.
    let windy = phases_of("hanging", |e| e.push(Effect::Wind(Wind::default())));
    assert!(windy.contains(&"wind".into()), "{windy:?}");
    let folding = phases_of("hanging", |e| {
        e.push(Effect::SelfCollision(SelfCollision::default()))
    });
    assert!(folding.contains(&"self-collision".into()), "{folding:?}");
    assert!(folding.contains(&"self-upkeep".into()), "{folding:?}");
    let limp = phases_of("hanging", |e| {
        e.retain(|e| !matches!(e, Effect::Bending(_)))
    });
    assert!(!limp.contains(&"bending".into()), "{limp:?}");
    let weightless = phases_of("sphere-drop", |e| {
        e.retain(|e| !matches!(e, Effect::Gravity(_) | Effect::Sphere(_)))
    });
    assert!(!weightless.contains(&"gravity".into()) && !weightless.contains(&"sphere".into()));
}

#[test]
fn a_scene_without_self_collision_does_no_self_collision_work() {
    let mut sim = Simulation::new(Scene::builtin("hanging").unwrap());
    sim.run(0.1);
    assert_eq!(sim.self_collision_work(), None);
    // Once the fold has come within reach of itself.
    let mut sim = Simulation::new(Scene::builtin("self-fold").unwrap());
    sim.run(0.5);
    let work = sim
        .self_collision_work()
        .expect("self-fold has self-collision");
    assert!(work.candidates > 0);
}

/// Self-contact's setup for the cloth is made with the simulation, once, and a run lists
/// it beside its own phases; effects set again (self-collision among them) build nothing
/// more; a scene without self-collision has none.
#[test]
fn self_contact_is_set_up_once_when_the_simulation_is_made() {
    let setups = |name: &str| {
        let mut sim = Simulation::new(Scene::builtin(name).unwrap());
        let first = sim.run(0.05);
        sim.set_effects(sim.effects().to_vec()).unwrap();
        let second = sim.run(0.05);
        let calls = |s: &clothsim::scene::RunSummary| s.phases.get(SELF_SETUP).map(|p| p.calls);
        (calls(&first), calls(&second))
    };
    assert_eq!(setups("self-fold"), (Some(1), None));
    assert_eq!(setups("hanging"), (None, None));
}

#[test]
fn an_absent_effect_changes_nothing_and_a_present_one_does() {
    // Bending by springs only acts when listed: without it the bend springs are not forces.
    let run = |bending: bool| {
        let mut sim = Simulation::new(Scene::builtin("hanging").unwrap());
        let mut effects = sim.effects().to_vec();
        if !bending {
            effects.retain(|e| *e != Effect::Bending(BendingModel::Springs));
        }
        sim.set_effects(effects).unwrap();
        sim.run(0.5);
        sim.state().pos.clone()
    };
    let (with, without) = (run(true), run(false));
    let moved = with
        .iter()
        .zip(&without)
        .map(|(a, b)| a.distance(*b))
        .fold(0.0f32, f32::max);
    assert!(moved > 1e-3, "bend springs made no difference: {moved} m");
}
