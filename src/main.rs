//! The `stereolab` command line.

use std::path::PathBuf;
use std::process::ExitCode;

use clap::{Parser, Subcommand};

use stereolab::plan::Plan;
use stereolab::scene::Scene;
use stereolab::{Error, Result, bench, effects, info, output, render};

#[derive(Parser)]
#[command(
    name = "stereolab",
    version,
    about = "A deterministic CPU rasterizer for stereoscopic rendering"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Render the outputs a scene asks for, as PNG files.
    Render {
        /// Scene file (TOML).
        scene: PathBuf,
        /// Output folder.
        #[arg(long, default_value = "out")]
        out: PathBuf,
        /// Image size WxH, overriding the scene's.
        #[arg(long)]
        size: Option<String>,
        /// Override a scene field: --set stereo.eye_separation=0.2 (repeatable).
        #[arg(long = "set", value_name = "KEY=VALUE")]
        sets: Vec<String>,
        /// Print the plan (which passes run for which outputs) and render nothing.
        #[arg(long)]
        explain: bool,
    },
    /// Print the derived cameras and the scene's parallax range.
    Info {
        /// Scene file (TOML).
        scene: PathBuf,
        /// Override a scene field (repeatable).
        #[arg(long = "set", value_name = "KEY=VALUE")]
        sets: Vec<String>,
    },
    /// Draw the slides' figures (rig top views, parallax plot) for a scene.
    Figures {
        /// Scene file (TOML).
        scene: PathBuf,
        /// Output folder.
        #[arg(long, default_value = "slides/figures")]
        out: PathBuf,
    },
    /// Measure accuracy knobs and speed: error and time side by side.
    Bench {
        /// Also write the rows as CSV.
        #[arg(long)]
        csv: Option<PathBuf>,
        /// Scene with the real model (default: assets/scenes/wuson.toml).
        #[arg(long)]
        scene: Option<PathBuf>,
        /// Repetitions per timing (median reported).
        #[arg(long, default_value_t = 15)]
        iterations: usize,
    },
    /// Autostereograms (SIRDS): from a scene, from a depth map (--depth), animated (--frames),
    /// or decoded back to depth (--decode).
    Sirds(stereolab::effects::sirds::cli::SirdsArgs),
}

fn parse_size(s: &str) -> Result<(u32, u32)> {
    let bad = || Error::invalid("--size", s, "expected WxH, e.g. 1024x768");
    let (w, h) = s.split_once(['x', 'X']).ok_or_else(bad)?;
    Ok((
        w.trim().parse().map_err(|_| bad())?,
        h.trim().parse().map_err(|_| bad())?,
    ))
}

fn run(cli: Cli) -> Result<()> {
    match cli.command {
        Command::Render {
            scene,
            out,
            size,
            sets,
            explain,
        } => {
            let mut s = Scene::load(&scene, &sets)?;
            if let Some(size) = size {
                let (w, h) = parse_size(&size)?;
                s.set_size(w, h)?;
            }
            let plan = Plan::new(&s.outputs);
            if explain {
                print!("{}", plan.explain());
                return Ok(());
            }
            let frame = render::render(&s, &plan)?;
            let paths = output::write_all(&frame, &s, &out)?;
            println!("rendered {} ({}x{})", scene.display(), s.width, s.height);
            for p in &frame.passes {
                println!(
                    "  pass {:?} {:?}: {:.2} ms, {} triangles, {} fragments, {} clipped, {} culled",
                    p.pass.view,
                    p.pass.shading,
                    p.time.as_secs_f64() * 1e3,
                    p.stats.triangles,
                    p.stats.fragments,
                    p.stats.clipped,
                    p.stats.culled
                );
            }
            if let Some(report) = effects::parallax::frame_budget_report(&frame, &s)? {
                print!("{report}");
            }
            for p in paths {
                println!("  wrote {}", p.display());
            }
            Ok(())
        }
        Command::Info { scene, sets } => {
            let s = Scene::load(&scene, &sets)?;
            print!("{}", info::describe(&s)?);
            Ok(())
        }
        Command::Figures { scene, out } => {
            let s = Scene::load(&scene, &[])?;
            for p in stereolab::figures::write_all(&s, &out)? {
                println!("wrote {}", p.display());
            }
            Ok(())
        }
        Command::Bench {
            csv,
            scene,
            iterations,
        } => {
            let mut opts = bench::BenchOptions {
                iterations,
                ..Default::default()
            };
            if let Some(s) = scene {
                opts.scene = s;
            }
            let rows = bench::run(&opts)?;
            print!("{}", bench::table(&rows));
            if let Some(path) = csv {
                bench::write_csv(&rows, &path)?;
            }
            Ok(())
        }
        Command::Sirds(args) => {
            print!("{}", stereolab::effects::sirds::cli::run(&args)?);
            Ok(())
        }
    }
}

fn main() -> ExitCode {
    match run(Cli::parse()) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::FAILURE
        }
    }
}
