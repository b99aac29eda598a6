//! `coma traj`: the root path a phrase or an expression curve asks for, drawn as a PNG.

use anyhow::{bail, Context, Result};
use clap::Args;
use coma::trajectory::Trajectory;
use std::path::PathBuf;

#[derive(Args)]
pub struct TrajArgs {
    /// A path phrase ("zigzag forward", "a circle clockwise") or a curve "x(t); z(t); t0; t1"
    /// in the sandboxed expression language.
    path: String,
    /// PNG to write.
    #[arg(long, short)]
    out: PathBuf,
    /// Length of the path in metres.
    #[arg(long, default_value_t = 6.0)]
    length: f64,
}

/// A path phrase, or "x(t); z(t); t0; t1".
fn trajectory_arg(text: &str) -> Result<Trajectory> {
    let pieces: Vec<&str> = text.split(';').map(str::trim).collect();
    if let [x, z, t0, t1] = pieces[..] {
        let number = |s: &str| {
            s.parse::<f64>()
                .map_err(|_| anyhow::anyhow!("'{s}' is not a number (t0 and t1 are numbers)"))
        };
        let spec = coma::trajectory::CurveSpec {
            x: x.to_string(),
            z: z.to_string(),
            t0: number(t0)?,
            t1: number(t1)?,
        };
        return Ok(Trajectory::Curve(spec));
    }
    Trajectory::from_text(text).ok_or_else(|| {
        anyhow::anyhow!(
            "no path shape in '{text}' (try \"a circle clockwise\", \"zigzag\", \"figure eight\", \
             or a curve \"sin(t); t; 0; 6.28\")"
        )
    })
}

pub fn run(args: TrajArgs) -> Result<()> {
    if !(args.length.is_finite() && args.length > 0.0 && args.length <= 1000.0) {
        bail!("--length must be a positive number of metres, at most 1000");
    }
    let trajectory = trajectory_arg(&args.path)?;
    let path = trajectory
        .validate()
        .and_then(|p| Ok(p.scaled_to(args.length)?.resample(200)?))
        .map_err(|e| anyhow::anyhow!("{}: {e}", trajectory.describe()))?;
    let options = coma::render::plot::PathPlotOptions {
        title: format!("{} ({:.1} m)", trajectory.describe(), args.length),
        ..Default::default()
    };
    let png = coma::render::plot::path_png(&path.points, None, &options)?;
    std::fs::write(&args.out, png).with_context(|| format!("writing {}", args.out.display()))?;
    if let Trajectory::Shape {
        shape: coma::trajectory::Shape::Circle(side),
    } = trajectory
    {
        let c = coma::trajectory::circle_report(&path.points, side.is_clockwise());
        println!(
            "{}: turned {:.0}° {}, closure error {:.3} m, mean distance to the circle {:.3} m",
            trajectory.describe(),
            c.total_turn_deg,
            if c.turned_clockwise {
                "clockwise"
            } else {
                "counter-clockwise"
            },
            c.closure_error_m,
            c.mean_radius_error_m
        );
    }
    println!("wrote {}", args.out.display());
    Ok(())
}
