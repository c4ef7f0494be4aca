//! `clothsim render`: a PNG of the state after some seconds, a numbered sequence, or a GIF.

use anyhow::{Result, bail};

use clothsim::view;

use super::args::RunArgs;
use super::paths::check_directory;

fn parse_size(size: &str) -> Result<(u32, u32)> {
    let parsed = size
        .split_once(['x', 'X'])
        .and_then(|(w, h)| Some((w.trim().parse::<u32>().ok()?, h.trim().parse::<u32>().ok()?)));
    match parsed {
        Some((w, h)) if w > 0 && h > 0 => Ok((w, h)),
        _ => bail!("--size must look like 1280x720, got `{size}`"),
    }
}

/// Where `render` writes.
pub struct Output<'a> {
    pub png: Option<&'a std::path::Path>,
    pub every: Option<u32>,
    pub dir: Option<&'a std::path::Path>,
    pub gif: Option<&'a std::path::Path>,
}

/// Renders the run as `output` asks, `size` pixels, with `overlay`s.
pub fn render(args: &RunArgs, size: &str, overlay: &str, output: Output<'_>) -> Result<()> {
    use clothsim::device::AdapterPreference;
    use clothsim::render::{GifWriter, Offscreen, RenderOptions, save_png};
    let (width, height) = parse_size(size)?;
    let options = RenderOptions::default()
        .with_overlays(overlay)
        .map_err(anyhow::Error::msg)?;
    if let Some(dir) = output.dir
        && !dir.is_dir()
    {
        bail!("--out-dir {}: not an existing directory", dir.display());
    }
    for path in [output.png, output.gif].into_iter().flatten() {
        check_directory(path)?;
    }
    if output.png.is_none() && output.dir.is_none() && output.gif.is_none() {
        bail!("give --out FILE.png, --out-dir DIR or --gif FILE.gif");
    }
    let mut sim = args.simulation()?;
    let camera = view::default_camera(&sim, width as f32 / height as f32);
    let mut offscreen = Offscreen::new(width, height, AdapterPreference::Any)?;
    let frames = (args.seconds / sim.params().step.dt as f64).round() as u64;
    if let Some(path) = output.png {
        for _ in 0..frames {
            sim.step_frame()?;
        }
        let image = offscreen.render(&view::frame(&sim), &camera, &options)?;
        save_png(&image, path)?;
        println!(
            "wrote {} ({}x{}, t = {:.3} s)",
            path.display(),
            width,
            height,
            sim.state().time
        );
        return Ok(());
    }
    let every = output.every.unwrap_or(1).max(1) as u64;
    let mut gif = match output.gif {
        Some(path) => Some(GifWriter::create(
            path,
            every as f64 * sim.params().step.dt as f64,
        )?),
        None => None,
    };
    let bar = indicatif::ProgressBar::new(frames / every + 1);
    bar.set_style(
        indicatif::ProgressStyle::with_template("{bar:40} {pos}/{len} frames {msg}")
            .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
    );
    let mut written = 0u64;
    for f in 0..=frames {
        if f > 0 {
            sim.step_frame()?;
        }
        if f % every == 0 {
            let image = offscreen.render(&view::frame(&sim), &camera, &options)?;
            if let Some(dir) = output.dir {
                save_png(&image, &dir.join(format!("frame_{written:05}.png")))?;
            }
            if let Some(g) = gif.as_mut() {
                g.add(&image)?;
            }
            written += 1;
            bar.inc(1);
        }
    }
    bar.finish_and_clear();
    if let Some(g) = gif {
        g.finish()?;
    }
    for (what, place) in [("", output.dir), (" as a GIF", output.gif)] {
        if let Some(p) = place {
            println!("wrote {written} frames{what} to {}", p.display());
        }
    }
    Ok(())
}
