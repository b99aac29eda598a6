//! `coma posture`: solve a named posture or a posture script, draw it, and check the solver.

use anyhow::{bail, Context, Result};
use clap::{Args, Subcommand, ValueEnum};
use coma::posture::check::{fuzz, round_trip_random, round_trip_scripts, RoundTrip};
use coma::posture::library::Library;
use coma::posture::script::PostureScript;
use coma::posture::solver::solve;
use coma::render::{FilmstripOptions, View};
use std::path::{Path, PathBuf};
use std::time::Instant;

#[derive(Args)]
#[command(args_conflicts_with_subcommands = true)]
pub struct PostureArgs {
    #[command(subcommand)]
    command: Option<PostureCommand>,
    #[command(flatten)]
    show: ShowArgs,
}

#[derive(Subcommand)]
enum PostureCommand {
    /// Solve scripts and read them back with the describer; prints the round-trip rate.
    Check(CheckArgs),
    /// List the named postures and their synonyms.
    List,
    /// Draw every named posture as a PNG into a folder.
    Filmstrips {
        /// Folder to write `<name>.png` files into.
        #[arg(long)]
        out: PathBuf,
    },
}

#[derive(Args)]
struct ShowArgs {
    /// A named posture ("T-pose", "squat"), a posture script as JSON, or @FILE with one.
    posture: Option<String>,
    /// Draw the solved pose into this PNG.
    #[arg(long)]
    png: Option<PathBuf>,
    /// Camera for --png.
    #[arg(long, value_enum, default_value_t = ViewArg::ThreeQuarter)]
    view: ViewArg,
    /// Print the solved joints (metres, Y up, facing +Z) as JSON.
    #[arg(long)]
    json: bool,
}

#[derive(Args)]
struct CheckArgs {
    /// A JSON file with a list of posture scripts to solve and read back (besides the library).
    #[arg(long)]
    scripts: Option<PathBuf>,
    /// Number of random valid scripts (constraints read off random balanced poses).
    #[arg(long, default_value_t = 300)]
    random: usize,
    /// Number of random and mutated inputs for the fuzz (0 to skip).
    #[arg(long, default_value_t = 10_000)]
    fuzz: usize,
    /// Seed of the random scripts and the fuzz.
    #[arg(long, default_value_t = 17)]
    seed: u64,
}

#[derive(Clone, Copy, ValueEnum)]
enum ViewArg {
    Front,
    Side,
    ThreeQuarter,
}

impl ViewArg {
    fn view(self) -> View {
        match self {
            ViewArg::Front => View::Front,
            ViewArg::Side => View::Side,
            ViewArg::ThreeQuarter => View::ThreeQuarter,
        }
    }
}

pub fn run(args: PostureArgs) -> Result<()> {
    match args.command {
        Some(PostureCommand::Check(check)) => run_check(check),
        Some(PostureCommand::List) => {
            for p in &Library::builtin().postures {
                println!("{}: {}", p.name, p.synonyms.join(", "));
            }
            Ok(())
        }
        Some(PostureCommand::Filmstrips { out }) => write_filmstrips(&out),
        None => show(args.show),
    }
}

fn read_script(text: &str) -> Result<PostureScript> {
    if let Some(path) = text.strip_prefix('@') {
        let json = std::fs::read_to_string(path).with_context(|| format!("reading {path}"))?;
        return Ok(PostureScript::parse(&json)?);
    }
    if text.trim_start().starts_with('{') {
        return Ok(PostureScript::parse(text)?);
    }
    match Library::builtin().get(text) {
        Some(p) => Ok(p.script.clone()),
        None => {
            let close: Vec<&str> = Library::builtin()
                .search(text)
                .iter()
                .take(5)
                .map(|p| p.name.as_str())
                .collect();
            bail!(
                "no posture is called '{text}'{}; `coma posture list` lists them",
                if close.is_empty() {
                    String::new()
                } else {
                    format!(" (did you mean {}?)", close.join(", "))
                }
            )
        }
    }
}

fn show(args: ShowArgs) -> Result<()> {
    let Some(text) = args.posture else {
        bail!("name a posture (`coma posture T-pose`), or use `coma posture check` / `list`");
    };
    let script = read_script(&text)?;
    let start = Instant::now();
    let solved = solve(&script, None);
    let ms = start.elapsed().as_secs_f64() * 1e3;
    println!("{}", script.name.as_deref().unwrap_or("posture script"));
    println!("  asks: {}", script.in_words());
    println!(
        "  solved in {ms:.1} ms: {} of {} constraints met; centre of mass {:.0} mm outside the support",
        script.constraints.len() - solved.unmet.len(),
        script.constraints.len(),
        solved.imbalance_m * 1e3
    );
    for c in &solved.unmet {
        println!("  not met: {c}");
    }
    if args.json {
        println!("{}", serde_json::to_string(&solved.pose.to_vec())?);
    }
    if let Some(png) = args.png {
        draw(&png, &script, &solved.pose, args.view.view())?;
        println!("wrote {}", png.display());
    }
    Ok(())
}

fn draw(
    path: &Path,
    script: &PostureScript,
    pose: &coma::skeleton::Pose,
    view: View,
) -> Result<()> {
    let options = FilmstripOptions {
        frames: 1,
        columns: 1,
        title: Some(script.name.clone().unwrap_or_else(|| "posture".into())),
        view,
        ..FilmstripOptions::default()
    };
    coma::render::write_filmstrip(path, &[*pose], &options)?;
    Ok(())
}

fn write_filmstrips(out: &Path) -> Result<()> {
    std::fs::create_dir_all(out).with_context(|| format!("creating {}", out.display()))?;
    for p in &Library::builtin().postures {
        let solved = solve(&p.script, None);
        let file: String = p
            .name
            .to_lowercase()
            .chars()
            .map(|c| if c.is_ascii_alphanumeric() { c } else { '-' })
            .collect();
        let path = out.join(format!("{file}.png"));
        draw(&path, &p.script, &solved.pose, View::ThreeQuarter)?;
        println!("wrote {}", path.display());
    }
    Ok(())
}

fn print_round_trip(what: &str, r: &RoundTrip) {
    println!(
        "{what}: {} scripts, {} of {} constraints read back ({:.1} %), {} scripts met in full, \
         {:.1} ms per pose; {} joint-limit breaks, {} poses below the floor",
        r.scripts,
        r.read_back,
        r.constraints,
        100.0 * r.rate(),
        r.scripts_met,
        r.mean_ms,
        r.limit_breaks,
        r.below_floor
    );
    for m in &r.misses {
        println!("  missed: {m}");
    }
}

fn run_check(args: CheckArgs) -> Result<()> {
    let clock = Instant::now();
    let now = || clock.elapsed().as_secs_f64() * 1e3;
    let library = Library::builtin();
    let named = round_trip_scripts(
        library.postures.iter().map(|p| (p.name.clone(), &p.script)),
        &now,
    );
    print_round_trip("named library", &named);
    if let Some(path) = &args.scripts {
        let text =
            std::fs::read_to_string(path).with_context(|| format!("reading {}", path.display()))?;
        let values: Vec<serde_json::Value> = serde_json::from_str(&text)
            .with_context(|| format!("{} is not a JSON list of scripts", path.display()))?;
        let scripts = values
            .into_iter()
            .enumerate()
            .map(|(i, v)| PostureScript::from_value(v).with_context(|| format!("script {}", i + 1)))
            .collect::<Result<Vec<_>>>()?;
        let given = round_trip_scripts(
            scripts.iter().enumerate().map(|(i, s)| {
                (
                    s.name
                        .clone()
                        .unwrap_or_else(|| format!("script {}", i + 1)),
                    s,
                )
            }),
            &now,
        );
        print_round_trip(&path.display().to_string(), &given);
    }
    if args.random > 0 {
        let random = round_trip_random(args.random, args.seed, &now);
        print_round_trip(
            &format!("random valid scripts (seed {})", args.seed),
            &random,
        );
    }
    if args.fuzz > 0 {
        let f = fuzz(args.fuzz, args.seed);
        println!(
            "fuzz (seed {}): {} inputs, {} refused with a message ({} without one), {} solved, \
             {} solved poses non-finite, past a joint limit or under the floor",
            args.seed, f.inputs, f.refused, f.silent_refusals, f.solved, f.bad_poses
        );
        for m in &f.sample_messages {
            println!("  e.g. {m}");
        }
    }
    Ok(())
}
