//! The spring runs against the plain formula, on every layout, both builds, both passes.

use super::*;
use crate::sim::forces::SpringBlock;
use crate::sim::kernels::TwoPasses;

/// The plain spring formula, spring by spring.
fn reference(
    a: &[u32],
    b: &[u32],
    rest: &[f32],
    k: &[f32],
    c: &[f32],
    pos: &[Vec3],
    vel: &[Vec3],
) -> Vec<Vec3> {
    let mut f = vec![Vec3::ZERO; pos.len()];
    for e in 0..a.len() {
        let (ia, ib) = (a[e] as usize, b[e] as usize);
        let d = pos[ib] - pos[ia];
        let len = d.length();
        if len > 1e-9 {
            let n = d / len;
            let t = (k[e] * (len - rest[e]) + c[e] * (vel[ib] - vel[ia]).dot(n)) * n;
            f[ia] += t;
            f[ib] -= t;
        }
    }
    f
}

/// The springs of a `w` × `h` grid's stencil `offsets` (columns, rows), from each
/// particle to its neighbour.
fn stencil(w: usize, h: usize, offsets: &[(usize, usize)]) -> (Vec<u32>, Vec<u32>) {
    let (mut a, mut b) = (Vec::new(), Vec::new());
    for p in 0..w * h {
        for &(di, dj) in offsets {
            let (i, j) = (p % w + di, p / w + dj);
            if i < w && j < h {
                a.push(p as u32);
                b.push((j * w + i) as u32);
            }
        }
    }
    (a, b)
}

/// A `w` × `h` grid's springs to the right, below, diagonally and two below, each with its
/// ends in an order `rnd` draws.
fn stencil_either_way(w: usize, h: usize, rnd: &mut impl FnMut() -> f32) -> (Vec<u32>, Vec<u32>) {
    let (mut a, mut b) = stencil(w, h, &[(1, 0), (0, 1), (1, 1), (0, 2)]);
    for (x, y) in a.iter_mut().zip(&mut b) {
        if rnd() >= 0.5 {
            std::mem::swap(x, y);
        }
    }
    (a, b)
}

/// `start` plus the forces, computed on component arrays.
fn on_components(runs: &SpringRuns, pos: &[Vec3], vel: &[Vec3], start: &[Vec3]) -> Vec<Vec3> {
    let n = pos.len();
    let (mut p, mut v, mut f) = <(Components, Components, Components)>::default();
    split(pos, &mut p, n);
    split(vel, &mut v, n);
    split(start, &mut f, n);
    runs.add_forces_components(&p, &v, &mut f);
    (0..n)
        .map(|i| Vec3::new(f[0][i], f[1][i], f[2][i]))
        .collect()
}

/// A scrambled cloth: a grid's stencil springs (long runs) plus random ones (runs of
/// one), in shuffled order and with ends swapped, over several blocks.
#[test]
fn runs_give_the_springs_forces_on_any_layout() {
    let (w, h) = (70usize, 40usize);
    let n = w * h;
    let mut rnd = crate::test_rng::uniform(12345);
    let pos: Vec<Vec3> = (0..n)
        .map(|p| {
            Vec3::new((p % w) as f32 * 0.01, (p / w) as f32 * -0.01, 0.0)
                + 0.002 * Vec3::new(rnd(), rnd(), rnd())
        })
        .collect();
    let vel: Vec<Vec3> = (0..n)
        .map(|_| Vec3::new(rnd(), rnd(), rnd()) - 0.5)
        .collect();
    let (mut a, mut b) = stencil(w, h, &[(1, 0), (0, 1), (1, 1), (2, 0)]);
    for _ in 0..500 {
        a.push((rnd() * n as f32) as u32 % n as u32);
        b.push((rnd() * n as f32) as u32 % n as u32);
    }
    // Shuffle and swap ends.
    for e in (1..a.len()).rev() {
        let o = (rnd() * e as f32) as usize;
        a.swap(e, o);
        b.swap(e, o);
        if rnd() < 0.5 {
            std::mem::swap(&mut a[e], &mut b[e]);
        }
    }
    let rest: Vec<f32> = a
        .iter()
        .zip(&b)
        .map(|(&i, &j)| pos[i as usize].distance(pos[j as usize]) * (0.9 + 0.2 * rnd()))
        .collect();
    let k: Vec<f32> = (0..a.len()).map(|_| 100.0 + 400.0 * rnd()).collect();
    let c: Vec<f32> = (0..a.len()).map(|_| 0.05 * rnd()).collect();
    let runs = SpringRuns::new(n, &a, &b, &rest, &k, &c);
    assert!(runs.blocks.len() >= 3, "the test spans several blocks");
    assert!(
        runs.run_count() < a.len() / 5,
        "grid springs fall into long runs"
    );
    let want = reference(&a, &b, &rest, &k, &c, &pos, &vel);
    let start = vec![Vec3::new(0.5, -1.0, 2.0); n];
    let mut got = start.clone();
    runs.add_forces(&pos, &vel, &mut got);
    let scale = want.iter().map(|f| f.length()).fold(0.0, f32::max);
    for p in 0..n {
        let err = (got[p] - start[p] - want[p]).length();
        assert!(
            err <= 1e-5 * scale,
            "particle {p}: {} vs {}",
            got[p] - start[p],
            want[p]
        );
    }
    // The same again (buffers reused), and with the blocks in parallel on one thread and
    // on two: identical bits.
    let mut again = start.clone();
    runs.add_forces(&pos, &vel, &mut again);
    assert!(got == again, "a rerun changed the forces");
    for threads in [1, 2] {
        // A fresh copy: no sums left over from another run can hide a block not done.
        let parallel = runs.clone().parallel_from(1);
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        let mut out = start.clone();
        pool.install(|| parallel.add_forces(&pos, &vel, &mut out));
        assert!(
            got == out,
            "parallel blocks on {threads} threads changed the forces"
        );
        let fresh = runs.clone().parallel_from(1);
        let out = pool.install(|| on_components(&fresh, &pos, &vel, &start));
        assert!(got == out, "on components, {threads} threads");
    }
    // On component arrays: the same bits.
    assert!(got == on_components(&runs, &pos, &vel, &start));
    // Buffers reused at another state: the forces there, as from runs never used (each
    // block's first run overwrites its slices, the rest of its buffers is zeroed).
    let moved: Vec<Vec3> = (pos.iter().enumerate())
        .map(|(p, x)| *x * 1.02 + Vec3::new(0.0, 0.0, 0.001 * (p % 3) as f32))
        .collect();
    let (mut reused, mut fresh) = (start.clone(), start.clone());
    runs.add_forces(&moved, &vel, &mut reused);
    SpringRuns::new(n, &a, &b, &rest, &k, &c).add_forces(&moved, &vel, &mut fresh);
    assert!(
        reused == fresh,
        "sums of the last state stayed in the buffers"
    );
    assert!(reused != got, "the moved state gave the same forces");
    // New strengths without rebuilding the runs: the same as runs built with them.
    let stiffer: Vec<f32> = k.iter().map(|k| 2.0 * k).collect();
    let mut changed = runs.clone();
    changed.set_strengths(&stiffer, &c);
    let rebuilt = SpringRuns::new(n, &a, &b, &rest, &stiffer, &c);
    let (mut x, mut y) = (start.clone(), start.clone());
    changed.add_forces(&pos, &vel, &mut x);
    rebuilt.add_forces(&pos, &vel, &mut y);
    assert!(x == y, "new strengths differ from runs built with them");
    assert!(x != got, "the strengths changed nothing");
}

/// Springs of a `w` × `h` grid's stencil `offsets`, 1 cm apart with jittered depths,
/// rest lengths and velocities (from `seed`), and their positions and velocities on
/// component arrays.
fn jittered_grid(
    w: usize,
    h: usize,
    seed: u64,
    offsets: &[(usize, usize)],
) -> (SpringRuns, Components, Components) {
    let n = w * h;
    let mut rnd = crate::test_rng::uniform(seed);
    let pos: Vec<Vec3> = (0..n)
        .map(|p| Vec3::new((p % w) as f32, -((p / w) as f32), rnd()) * 0.01)
        .collect();
    let vel: Vec<Vec3> = (0..n).map(|_| Vec3::new(rnd(), rnd(), rnd())).collect();
    let (a, b) = stencil(w, h, offsets);
    let rest: Vec<f32> = (0..a.len()).map(|_| 0.008 + 0.01 * rnd()).collect();
    let (k, c) = (vec![400.0; a.len()], vec![0.02; a.len()]);
    let (mut p, mut v) = (Components::default(), Components::default());
    split(&pos, &mut p, n);
    split(&vel, &mut v, n);
    (SpringRuns::new(n, &a, &b, &rest, &k, &c), p, v)
}

/// The block passes compiled plainly and for AVX2 with FMA (the one the CPU runs)
/// give the same bits: the fused multiply-adds are exact either way. (On a CPU without
/// AVX2 and FMA both sides are the plain build, and this proves nothing there; CI's
/// machines have both.)
#[test]
fn the_plain_and_the_vector_build_give_the_same_bits() {
    let (runs, p, v) = jittered_grid(40, 30, 7, &[(1, 0), (0, 1), (1, 1), (0, 2)]);
    let pass = runs.force_pass(&p, &v);
    let mut buffers = Vec::new();
    runs.size_buffers(&mut buffers);
    let mut plain = buffers.clone();
    for (block, (buf, twin)) in runs.blocks.iter().zip(buffers.iter_mut().zip(&mut plain)) {
        runs.block_pass(block, buf, &pass);
        runs.each_run(block, twin, &pass);
        assert!(
            buf.first == twin.first && buf.second == twin.second,
            "block at {}",
            block.lo
        );
    }
    assert!(
        buffers[0].first[0].iter().any(|&f| f != 0.0),
        "no forces at all"
    );
}

/// [`TwoPasses::write_to`] overwrites what was there with the bits
/// [`TwoPasses::add_to`] adds to zeros: over ranges that start and end inside blocks,
/// span several, and reach past the last particle (which get zero).
#[test]
fn written_sums_are_the_added_ones_whatever_was_there() {
    let (runs, p, v) = jittered_grid(70, 40, 31, &[(1, 0), (0, 1), (1, 1), (2, 0)]);
    let n = runs.particles;
    assert!(runs.blocks.len() >= 3, "the test spans several blocks");
    let mut two = TwoPasses::of(&runs);
    let blocks = two.blocks();
    (0..blocks.len()).for_each(|b| blocks.fill(b, &p, &v));
    let past = n + 40;
    let ranges = [
        0..past,
        5..1000,
        1000..2048,
        1500..2600,
        2040..past,
        n - 3..past,
    ];
    for range in ranges {
        let len = range.len();
        let mut added: Components = std::array::from_fn(|_| vec![0.0; len]);
        two.add_to(range.clone(), added.each_mut().map(|a| &mut a[..]));
        let mut written: Components = std::array::from_fn(|_| vec![f32::NAN; len]);
        two.write_to(range.clone(), written.each_mut().map(|a| &mut a[..]));
        assert!(written == added, "{range:?}");
        assert!(added[0].iter().any(|&f| f != 0.0), "{range:?}: no forces");
    }
}

/// Block products against the plain per-spring sum, on one thread and on two.
#[test]
fn block_products_are_each_springs_block_times_the_other_end() {
    let (w, h) = (60usize, 50usize);
    let n = w * h;
    let mut rnd = crate::test_rng::uniform(99);
    let (a, b) = stencil_either_way(w, h, &mut rnd);
    // Random α, β and (not unit) n: every number of a block weighs in.
    let blocks: Vec<SpringBlock> = (0..a.len())
        .map(|_| SpringBlock {
            alpha: rnd() - 0.5,
            beta: rnd() - 0.5,
            n: Vec3::new(rnd() - 0.5, rnd() - 0.5, rnd() - 0.5),
        })
        .collect();
    let u: Vec<Vec3> = (0..n).map(|_| Vec3::new(rnd(), rnd(), rnd())).collect();
    let mut want = vec![Vec3::ZERO; n];
    for e in 0..a.len() {
        let (i, j) = (a[e] as usize, b[e] as usize);
        want[i] += blocks[e].matrix() * u[j];
        want[j] += blocks[e].matrix() * u[i];
    }
    let zero = vec![0.0; a.len()];
    let runs = SpringRuns::new(n, &a, &b, &zero, &zero, &zero);
    let mut s: Projectors = Default::default();
    runs.in_order(|e| blocks[e].numbers(), &mut s);
    let mut uc = Components::default();
    split(&u, &mut uc, n);
    let product = |runs: &SpringRuns| {
        let mut out = Components::default();
        crate::sim::kernels::zeroed(&mut out, n);
        runs.add_block_products(&s, &uc, &mut out);
        out
    };
    let got = product(&runs);
    let scale = want.iter().map(|v| v.length()).fold(0.0, f32::max);
    for p in 0..n {
        let g = Vec3::new(got[0][p], got[1][p], got[2][p]);
        assert!((g - want[p]).length() <= 1e-5 * scale, "particle {p}");
    }
    for threads in [1, 2] {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        let parallel = runs.clone().parallel_from(1);
        assert!(
            pool.install(|| product(&parallel)) == got,
            "{threads} threads"
        );
    }
}

/// A plain grid's stencil: the ends of its rows are filled, so each offset is one run
/// per block, not one per row; the fillers add nothing.
#[test]
fn row_ends_are_filled_so_each_offset_is_one_run_per_block() {
    let (w, h) = (50usize, 60usize);
    let n = w * h;
    let offsets = [(1, 0), (0, 1), (1, 1), (2, 0)];
    let (a, b) = stencil(w, h, &offsets);
    let pos: Vec<Vec3> = (0..n)
        .map(|p| Vec3::new((p % w) as f32, (p / w) as f32, (p % 7) as f32) * 0.01)
        .collect();
    let vel: Vec<Vec3> = (0..n).map(|p| Vec3::splat((p % 5) as f32 - 2.0)).collect();
    let rest = vec![0.008; a.len()];
    let (k, c) = (vec![300.0; a.len()], vec![0.02; a.len()]);
    let runs = SpringRuns::new(n, &a, &b, &rest, &k, &c);
    assert!(
        runs.run_count() <= offsets.len() * runs.blocks.len(),
        "{} runs for {} offsets in {} blocks",
        runs.run_count(),
        offsets.len(),
        runs.blocks.len()
    );
    let want = reference(&a, &b, &rest, &k, &c, &pos, &vel);
    let mut got = vec![Vec3::ZERO; n];
    runs.add_forces(&pos, &vel, &mut got);
    let scale = want.iter().map(|f| f.length()).fold(0.0, f32::max);
    for p in 0..n {
        assert!((got[p] - want[p]).length() <= 1e-5 * scale, "particle {p}");
    }
}

/// The same runs code computes in `f64`: on a cloth near rest, where each force is a
/// difference of nearly equal terms, the `f64` runs match the formula evaluated in `f64`
/// spring by spring to near `f64` rounding, many orders of magnitude closer than the
/// `f32` runs can; and the `f32` runs agree with both to `f32` rounding.
#[test]
fn the_runs_compute_in_f64_from_the_same_code() {
    let (w, h) = (50usize, 30usize);
    let n = w * h;
    let mut rnd = crate::test_rng::uniform(777);
    let spacing = 0.02f64;
    // Positions within a micrometre of rest, velocities small: forces of ~1e-4 N from
    // stretches of ~1e-6 m on 2 cm springs.
    let pos: Vec<[f64; 3]> = (0..n)
        .map(|p| {
            let jitter = 1e-6 * (rnd() as f64 - 0.5);
            [
                (p % w) as f64 * spacing + jitter,
                (p / w) as f64 * -spacing,
                0.0,
            ]
        })
        .collect();
    let vel: Vec<[f64; 3]> = (0..n).map(|_| [0.0, 1e-3 * rnd() as f64, 0.0]).collect();
    let (a, b) = stencil(w, h, &[(1, 0), (0, 1), (1, 1)]);
    // The rest lengths of the grid without the jitter.
    let rest: Vec<f64> = (a.iter().zip(&b))
        .map(|(&i, &j)| {
            let (i, j) = (i as usize, j as usize);
            let (di, dj) = (j % w - i % w, j / w - i / w);
            spacing * ((di * di + dj * dj) as f64).sqrt()
        })
        .collect();
    let (k, c) = (vec![400.0f64; a.len()], vec![0.02f64; a.len()]);

    // The formula in f64, spring by spring.
    let mut exact = vec![[0.0f64; 3]; n];
    for e in 0..a.len() {
        let (ia, ib) = (a[e] as usize, b[e] as usize);
        let d: [f64; 3] = std::array::from_fn(|x| pos[ib][x] - pos[ia][x]);
        let len = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
        let along: f64 = (0..3)
            .map(|x| (vel[ib][x] - vel[ia][x]) * d[x])
            .sum::<f64>()
            / len;
        let g = (k[e] * (len - rest[e]) + c[e] * along) / len;
        for x in 0..3 {
            exact[ia][x] += g * d[x];
            exact[ib][x] -= g * d[x];
        }
    }

    fn components<R: Real>(v: &[[f64; 3]], of: impl Fn(f64) -> R) -> Components<R> {
        std::array::from_fn(|x| v.iter().map(|p| of(p[x])).collect())
    }
    fn forces<R: Real>(
        runs: &SpringRuns<R>,
        pos: &Components<R>,
        vel: &Components<R>,
    ) -> Vec<[f64; 3]> {
        let mut f: Components<R> = Default::default();
        crate::sim::kernels::zeroed(&mut f, pos[0].len());
        runs.add_forces_components(pos, vel, &mut f);
        (0..pos[0].len())
            .map(|i| std::array::from_fn(|x| f[x][i].to_f64()))
            .collect()
    }
    let worst = |f: &[[f64; 3]]| {
        (f.iter().zip(&exact))
            .flat_map(|(f, e)| (0..3).map(move |x| (f[x] - e[x]).abs()))
            .fold(0.0f64, f64::max)
    };
    let scale = exact.iter().flatten().fold(0.0f64, |m, v| m.max(v.abs()));
    assert!(scale > 1e-5, "the forces are not negligible: {scale:e}");

    let runs64 = SpringRuns::<f64>::new(n, &a, &b, &rest, &k, &c);
    let f64_error = worst(&forces(
        &runs64,
        &components(&pos, |v| v),
        &components(&vel, |v| v),
    ));
    let as32 = |v: &[f64]| v.iter().map(|&x| x as f32).collect::<Vec<f32>>();
    let runs32 = SpringRuns::<f32>::new(n, &a, &b, &as32(&rest), &as32(&k), &as32(&c));
    let f32_error = worst(&forces(
        &runs32,
        &components(&pos, |v| v as f32),
        &components(&vel, |v| v as f32),
    ));
    // f64: rounding of ~1e-16 relative on positions of ~1 m, over stretches of ~1e-6 m.
    assert!(
        f64_error < 1e-10 * scale,
        "f64 runs off by {f64_error:e} of {scale:e}"
    );
    // f32 positions round to ~1e-7 m: a few per cent of the stretch is lost (measured: 6 %
    // of the largest force, against 4e-15 N in f64).
    assert!(
        f32_error > 1e6 * f64_error,
        "f32 {f32_error:e} vs f64 {f64_error:e}"
    );
    assert!(
        f32_error < 0.2 * scale,
        "f32 runs off by {f32_error:e} of {scale:e}"
    );
}

/// One spring's block and `K_x·(v_b − v_a)` by the formula, spring by spring:
/// `None` for coincident ends.
fn by_formula(d: Vec3, w: Vec3, (rest, k, c, h): (f32, f32, f32, f32)) -> Option<([f32; 5], Vec3)> {
    let len = d.length();
    if len <= 1e-9 {
        return None;
    }
    let n = d / len;
    let s = (1.0 - rest / len).max(0.0);
    let (alpha, beta) = (h * h * k * s, h * c + h * h * k * (1.0 - s));
    let dfdx_w = k * s * w + k * (1.0 - s) * n.dot(w) * n;
    Some(([alpha, beta, n.x, n.y, n.z], dfdx_w))
}

/// A 60 × 50 grid's stencil springs (ends in either order, several blocks) and some
/// random ones, stretched and compressed (the transverse stiffness clamps), two of them
/// with coincident ends: every spring's block in run order and the sums at its ends are
/// the formula's, and one thread and two give the same bits.
#[test]
fn system_blocks_are_each_springs_by_the_formula_on_any_number_of_threads() {
    let (w, rows) = (60usize, 50usize);
    let n = w * rows;
    let mut rnd = crate::test_rng::uniform(4242);
    let mut pos: Vec<Vec3> = (0..n)
        .map(|p| Vec3::new((p % w) as f32, -((p / w) as f32), rnd()) * 0.01)
        .collect();
    let vel: Vec<Vec3> = (0..n)
        .map(|_| Vec3::new(rnd(), rnd(), rnd()) - 0.5)
        .collect();
    let (mut a, mut b) = stencil_either_way(w, rows, &mut rnd);
    for _ in 0..300 {
        a.push((rnd() * n as f32) as u32 % n as u32);
        b.push((rnd() * n as f32) as u32 % n as u32);
    }
    // Coincident ends: particle 1 and 61 on top of their stencil neighbours 0 and 60.
    pos[1] = pos[0];
    pos[61] = pos[60];
    let rest: Vec<f32> = (0..a.len()).map(|_| 0.005 + 0.02 * rnd()).collect();
    let k: Vec<f32> = (0..a.len()).map(|_| 100.0 + 900.0 * rnd()).collect();
    let c: Vec<f32> = (0..a.len()).map(|_| 0.05 * rnd()).collect();
    let h = 1.0 / 240.0;
    let runs = SpringRuns::new(n, &a, &b, &rest, &k, &c);
    let (mut p, mut v) = (Components::default(), Components::default());
    split(&pos, &mut p, n);
    split(&vel, &mut v, n);
    let assemble = |runs: &SpringRuns| {
        let mut blocks = Projectors::default();
        let mut sums = SystemSums::default();
        for s in [&mut sums.diagonal, &mut sums.off_diagonal, &mut sums.dfdx_v] {
            *s = std::array::from_fn(|_| vec![0.0; n]);
        }
        runs.add_system_blocks(&p, &v, h, &mut blocks, &mut sums);
        (blocks, sums)
    };
    let (blocks, sums) = assemble(&runs);

    let (mut diagonal, mut dfdx) = (vec![[0.0f32; 6]; n], vec![Vec3::ZERO; n]);
    let mut want_blocks = vec![None; a.len()];
    let (mut stretched, mut compressed, mut coincident) = (0, 0, 0);
    for e in 0..a.len() {
        let (i, j) = (a[e] as usize, b[e] as usize);
        if i == j {
            continue;
        }
        let d = pos[j] - pos[i];
        let Some((block, g)) = by_formula(d, vel[j] - vel[i], (rest[e], k[e], c[e], h)) else {
            coincident += 1;
            want_blocks[e] = Some([0.0; 5]);
            continue;
        };
        if d.length() > rest[e] {
            stretched += 1;
        } else {
            compressed += 1;
        }
        let [al, be, x, y, z] = block;
        let entries = [
            al + be * x * x,
            al + be * y * y,
            al + be * z * z,
            be * x * y,
            be * x * z,
            be * y * z,
        ];
        for end in [i, j] {
            for (s, e) in diagonal[end].iter_mut().zip(entries) {
                *s += e;
            }
        }
        dfdx[i] += g;
        dfdx[j] -= g;
        want_blocks[e] = Some(block);
    }
    assert!(stretched > 100 && compressed > 100 && coincident == 2);

    for (place, e) in runs.places() {
        let got = blocks.each_ref().map(|b| b[place]);
        let mut want = want_blocks[e].expect("a spring from a particle to itself has no place");
        // The runs take each spring from its lower-numbered end.
        if a[e] > b[e] {
            want[2..].iter_mut().for_each(|x| *x = -*x);
        }
        for (g, w) in got.iter().zip(want) {
            assert!(
                (g - w).abs() <= 1e-6 * (1.0 + w.abs()),
                "spring {e}: {got:?} vs {want:?}"
            );
        }
    }
    let largest = |v: &[f32]| v.iter().fold(0.0f32, |m, x| m.max(x.abs()));
    let scale = diagonal.iter().map(|d| largest(d)).fold(0.0, f32::max);
    let g_scale = dfdx.iter().map(|g| g.length()).fold(0.0, f32::max);
    assert!(scale > 0.0 && g_scale > 0.0);
    for i in 0..n {
        let got = [
            sums.diagonal[0][i],
            sums.diagonal[1][i],
            sums.diagonal[2][i],
            sums.off_diagonal[0][i],
            sums.off_diagonal[1][i],
            sums.off_diagonal[2][i],
        ];
        for (g, w) in got.iter().zip(diagonal[i]) {
            assert!(
                (g - w).abs() <= 1e-5 * scale,
                "particle {i}: {got:?} vs {:?}",
                diagonal[i]
            );
        }
        let g = Vec3::new(sums.dfdx_v[0][i], sums.dfdx_v[1][i], sums.dfdx_v[2][i]);
        assert!(
            (g - dfdx[i]).length() <= 1e-5 * g_scale,
            "particle {i}: {g} vs {}",
            dfdx[i]
        );
    }

    for threads in [1, 2] {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .expect("a thread pool");
        let parallel = runs.clone().parallel_from(1);
        let (b2, s2) = pool.install(|| assemble(&parallel));
        assert!(b2 == blocks, "{threads} threads: the blocks");
        let same = [
            (&s2.diagonal, &sums.diagonal),
            (&s2.off_diagonal, &sums.off_diagonal),
            (&s2.dfdx_v, &sums.dfdx_v),
        ];
        assert!(
            same.iter().all(|(x, y)| x == y),
            "{threads} threads: the sums"
        );
    }
}
