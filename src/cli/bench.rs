//! `clothsim bench`: the speed of the bench cloth per size, integrator and thread count.

use anyhow::{Context, Result, bail};

use clothsim::bench::{BENCH_SECONDS, reference_sag};
use clothsim::gpu::{Backend, GPU_INTEGRATORS};
use clothsim::sim::{IntegratorKind, Precision};

/// The bench's rows: each thread count × size × integrator, for `seconds` of simulated time.
pub struct BenchRuns<'a> {
    pub sizes: &'a [u32],
    pub integrators: &'a [IntegratorKind],
    pub threads: &'a [usize],
    pub seconds: f64,
}

/// Runs and prints `runs`' rows (JSON with `json`).
pub fn bench(
    runs: &BenchRuns<'_>,
    json: bool,
    backend: Backend,
    precision: Precision,
) -> Result<()> {
    let BenchRuns {
        sizes,
        integrators,
        threads,
        seconds,
    } = *runs;
    if let Some(&n) = sizes.iter().find(|&&n| !(3..=2048).contains(&n)) {
        bail!("--sizes: {n} particles per side is outside 3..=2048");
    }
    clothsim::bench::bench_frames(seconds).context("--seconds")?;
    check_threads(threads)?;
    if backend == Backend::Gpu && precision != Precision::F32 {
        bail!("--backend gpu computes in f32 only, not {precision}");
    }
    if backend == Backend::Gpu
        && let Some(k) = integrators.iter().find(|k| !GPU_INTEGRATORS.contains(k))
    {
        let runs: Vec<&str> = GPU_INTEGRATORS.iter().map(|k| k.name()).collect();
        bail!(
            "--backend gpu runs {} only, not {}",
            runs.join(", "),
            k.name()
        );
    }
    if !json {
        println!(
            "{:>5} {:<20} {:>7} {:>9} {:>12} {:>9} {:>9} {:>12} {:>10} {:>10}  sag",
            "N",
            "integrator",
            "threads",
            "substeps",
            "µs/substep",
            "median fr",
            "best fr",
            "substeps/s",
            "sag m",
            "reference",
        );
    }
    // The GPU rows do not depend on the CPU threads: once.
    let threads = if backend == Backend::Gpu {
        &threads[..threads.len().min(1)]
    } else {
        threads
    };
    for &t in threads {
        let pool = pool(t)?;
        for &n in sizes {
            for &k in integrators {
                let row = match backend {
                    Backend::Cpu => {
                        pool.install(|| clothsim::bench::bench_in(n, k, precision, seconds))?
                    }
                    // On this thread, not the pool's: a GL device (llvmpipe through EGL) is
                    // current on the thread that made it, and a pool's thread still tearing
                    // that down while the process exits corrupts the heap (a crash at exit
                    // in a few runs in a hundred).
                    Backend::Gpu => clothsim::bench::bench_gpu(n, k, seconds)?,
                };
                if json {
                    println!("{}", serde_json::to_string(&row)?);
                } else {
                    let verdict = match (row.finite, row.sag_ok, row.sag_error) {
                        (false, _, _) => "diverged".to_string(),
                        (true, Some(ok), Some(e)) => {
                            format!(
                                "{:.2} % off{}",
                                100.0 * e,
                                if ok {
                                    ""
                                } else {
                                    " (too far: the speed does not count)"
                                }
                            )
                        }
                        _ if reference_sag(n, BENCH_SECONDS).is_some() => {
                            "no reference at this time (2 s)".to_string()
                        }
                        _ => "no reference".to_string(),
                    };
                    let frame = |us: Option<f64>| us.map_or("—".into(), |us| format!("{us:.1}"));
                    println!(
                        "{:>5} {:<20} {:>7} {:>9} {:>12.1} {:>9} {:>9} {:>12.0} {:>10.5} {:>10}  {}",
                        row.n,
                        row.integrator,
                        row.threads,
                        row.substeps_per_frame,
                        row.us_per_substep,
                        frame(row.median_frame_us),
                        frame(row.best_frame_us),
                        row.substeps_per_second,
                        row.sag_m,
                        row.reference_sag_m
                            .map_or("—".into(), |r| format!("{r:.5}")),
                        verdict
                    );
                }
            }
        }
    }
    Ok(())
}

/// Runs and prints the contact bench: one row per thread count × obstacle size, and the
/// ratio of the large obstacle's phase to the small one's.
pub fn contact_bench(threads: &[usize], json: bool) -> Result<()> {
    use clothsim::bench_contact::{CONTACT_TRIANGLES, contact_one};
    check_threads(threads)?;
    if !json {
        println!(
            "{:>9} {:>9} {:>7} {:>8} {:>14} {:>13} {:>9} {:>8}",
            "particles",
            "triangles",
            "threads",
            "substeps",
            "obstacle µs/ss",
            "springs µs/ss",
            "× springs",
            "resting",
        );
    }
    for &t in threads {
        let pool = pool(t)?;
        let rows = (CONTACT_TRIANGLES.iter())
            .map(|&n| pool.install(|| contact_one(n)))
            .collect::<Result<Vec<_>, _>>()?;
        for row in &rows {
            if json {
                println!("{}", serde_json::to_string(row)?);
            } else {
                println!(
                    "{:>9} {:>9} {:>7} {:>8} {:>14.1} {:>13.1} {:>9.1} {:>8}",
                    row.particles,
                    row.triangles,
                    row.threads,
                    row.substeps,
                    row.obstacle_us,
                    row.springs_us,
                    row.obstacle_us / row.springs_us,
                    row.resting
                );
            }
        }
        if let [small, large] = &rows[..]
            && !json
        {
            println!(
                "  {} threads: the obstacle phase with {} triangles costs {:.2}× the phase with {}",
                t,
                large.triangles,
                large.obstacle_us / small.obstacle_us,
                small.triangles
            );
        }
    }
    Ok(())
}

/// Runs and prints the crumple bench: one row per thread count × grid size × integrator,
/// each the medians of `repeat` runs, the rows run in turn `repeat` times over (so that a
/// swing in the machine's load falls on every row alike).
pub fn crumple_bench(
    quads: &[u32],
    integrators: Option<&[IntegratorKind]>,
    threads: &[usize],
    repeat: u32,
    json: bool,
) -> Result<()> {
    use clothsim::bench_crumple::{crumple_one, median_row};
    check_threads(threads)?;
    if let Some(&q) = quads.iter().find(|&&q| !(1..=2048).contains(&q)) {
        bail!("--quads: {q} is outside 1..=2048");
    }
    if !(1..=100).contains(&repeat) {
        bail!("--repeat: {repeat} is outside 1..=100");
    }
    // The scene's own integrator (`None`), or each asked for.
    let integrators: Vec<Option<IntegratorKind>> =
        integrators.map_or(vec![None], |ks| ks.iter().copied().map(Some).collect());
    let pools = (threads.iter())
        .map(|&t| pool(t))
        .collect::<Result<Vec<_>>>()?;
    let rows: Vec<(&rayon::ThreadPool, u32, Option<IntegratorKind>)> = (pools.iter())
        .flat_map(|p| quads.iter().map(move |&q| (p, q)))
        .flat_map(|(p, q)| integrators.iter().map(move |&k| (p, q, k)))
        .collect();
    let mut runs = vec![Vec::new(); rows.len()];
    for _ in 0..repeat {
        for (&(pool, q, k), runs) in rows.iter().zip(&mut runs) {
            runs.push(pool.install(|| crumple_one(q, k))?);
        }
    }
    if !json {
        println!(
            "{:>6} {:>9} {:<20} {:>7} {:>8} {:>11} {:>9} {:>13} {:>13} {:>9} {:>10} {:>9} {:>11} {:>9} {:>9}",
            "quads",
            "particles",
            "integrator",
            "threads",
            "substeps",
            "wall/sim s",
            "setup ms",
            "contact µs/ss",
            "springs µs/ss",
            "× springs",
            "self µs/ss",
            "self ×",
            "pairs/part.",
            "searches",
            "refreshes",
        );
    }
    for row in runs.iter().filter_map(|runs| median_row(runs)) {
        if json {
            println!("{}", serde_json::to_string(&row)?);
        } else {
            println!(
                "{:>6} {:>9} {:<20} {:>7} {:>8} {:>11.2} {:>9.1} {:>13.1} {:>13.1} {:>9} {:>10.1} {:>9} {:>11.4} {:>9.2} {:>9.2}",
                row.quads,
                row.particles,
                row.integrator,
                row.threads,
                row.substeps,
                row.wall_per_second,
                row.setup_ms,
                row.contact_us,
                row.springs_us,
                ratio(row.contact_per_springs),
                row.self_contact_us,
                ratio(row.self_per_springs),
                row.pairs_per_particle,
                row.searches_per_substep,
                row.refreshes_per_substep,
            );
            if let Some(fallback) = &row.fell_back_to {
                println!(
                    "       (the stability guard fell back to {fallback}: the row counts its \
                     substeps too)"
                );
            }
            if let Some(line) = row.beside_targets() {
                println!("       {line}");
            }
        }
    }
    Ok(())
}

/// A ratio to one decimal, or "-" for none (0: nothing to compare with).
fn ratio(x: f64) -> String {
    if x > 0.0 {
        format!("{x:.1}")
    } else {
        "-".to_string()
    }
}

/// A pool of `t` threads for one bench row's runs.
fn pool(t: usize) -> Result<rayon::ThreadPool> {
    rayon::ThreadPoolBuilder::new()
        .num_threads(t)
        .build()
        .with_context(|| format!("cannot start {t} threads"))
}

/// Refuses a thread count outside 1..=256.
fn check_threads(threads: &[usize]) -> Result<()> {
    if let Some(&t) = threads.iter().find(|&&t| !(1..=256).contains(&t)) {
        bail!("--threads: {t} is outside 1..=256");
    }
    Ok(())
}
