//! `coma posture`: solve a named posture or a posture script, draw it, check the solver, and
//! measure motions made of key poses against the real test motions (`coma posture motions`).

use anyhow::{bail, Context, Result};
use clap::{Args, Subcommand, ValueEnum};
use coma::agents::llm::UreqTransport;
use coma::agents::pipeline;
use coma::dataset::motions::MotionSet;
use coma::dataset::Split;
use coma::eval::references::reference_motions;
use coma::executor::block_on;
use coma::features::{
    features_to_joints, features_to_joints_with_final, joints_to_features, with_reference_bones,
};
use coma::posture::check::{fuzz, round_trip_random, round_trip_scripts, RoundTrip};
use coma::posture::library::Library;
use coma::posture::measure::{self, Measure, RealReference};
use coma::posture::script::PostureScript;
use coma::posture::solver::{pose_of, rest_angles, solve};
use coma::posture::track::{lay_tracks, PostureTrack, TrackSpan, DEFAULT_TRANSITION_SECONDS};
use coma::render::{FilmstripOptions, View};
use coma::session::{Command, Llm, Outcome};
use coma::skeleton::{BodyPart, Offsets, Pose};
use coma::timing::FPS;
use std::ops::Range;
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
    /// Motions from key poses held to the real test motions: foot skating, lowest joint and
    /// the fastest joint outside flight, for every named posture and movement of the library
    /// built by the go stage from standing, and (with --prompts) for the posture segments of
    /// the engine's runs of a prompt set.
    Motions(MotionsArgs),
}

#[derive(Args)]
struct MotionsArgs {
    /// A prompt set (eval/posture_prompts.json): run each prompt as `coma run` does, with no
    /// LLM, and measure the frames of its posture segments.
    #[arg(long)]
    prompts: Option<PathBuf>,
    /// Seed of the runs.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Review rounds per segment of the runs (K), as `coma run --rounds`.
    #[arg(long, default_value_t = coma::agents::pipeline::DEFAULT_ROUNDS)]
    rounds: usize,
    /// Dataset (from `coma data build`) whose test motions give the reference figures.
    #[arg(long, default_value = "data/coma")]
    data: PathBuf,
    /// Folder of the model for the runs.
    #[arg(long, default_value = "static/models")]
    models: PathBuf,
    /// Folder to write each library motion into, as a filmstrip (`<name>.png`) and joint
    /// positions (`<name>.npy`, frames × 22 × 3, metres).
    #[arg(long)]
    out: Option<PathBuf>,
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
        Some(PostureCommand::Motions(motions)) => run_motions(motions),
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
    let keys = round_trip_scripts(
        library.actions.iter().flat_map(|a| {
            a.keys.iter().map(move |k| {
                let key = k.script.name.as_deref().unwrap_or("key");
                (format!("{}: {key}", a.name), &k.script)
            })
        }),
        &now,
    );
    print_round_trip("key poses of the movements", &keys);
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

/// One measured motion: what it is (for a run, where its frames lie), whether key poses drive
/// the whole body (or are held on some parts of a generated motion), and its figures.
struct Measured {
    name: String,
    whole_body: bool,
    measure: Measure,
    /// For a posture held on some parts: the same frames of the generated motion decoded
    /// without it, to tell what the held parts add from what the motion under them does.
    without: Option<Measure>,
}

/// A track laid over a standing rest pose as the engine lays a posture segment: half a second
/// of standing, the track's key poses with the way out into standing again (the time the
/// built-in planner gives such a segment), a second of standing; then put on the one skeleton
/// as the engine returns every motion (features on the reference bones). Returns the motion,
/// the notes and the frames the key poses made (from the last standing frame before them).
fn from_rest(track: &PostureTrack) -> Result<(Vec<Pose>, Vec<String>, Range<usize>)> {
    let rest = pose_of(&rest_angles());
    let lead = (0.5 * FPS) as usize;
    let span = ((track.natural_seconds() + DEFAULT_TRANSITION_SECONDS) * FPS).round() as usize;
    let base = vec![rest; lead + span + FPS as usize];
    let spans = [TrackSpan {
        frames: lead..lead + span,
        track,
    }];
    let (laid, notes) = lay_tracks(&base, &spans, Library::builtin_bridges());
    // Frames the key poses added (or, when they needed less time, took away).
    let grown = laid.len() as isize - base.len() as isize;
    // As `Session::motion` does: features of the joints (the last pose becomes the last row's
    // velocities), on the reference bones, and the joints they describe.
    let (features, _) = joints_to_features(&laid, &Offsets::reference())?;
    let shown = features_to_joints(&with_reference_bones(&features));
    // The key poses end in the next frame's shape, which they include.
    let end = (((lead + span + 1) as isize + grown).max(lead as isize) as usize).min(shown.len());
    Ok((shown, notes, lead - 1..end))
}

/// Every named posture (held from standing on the whole body) and movement of the library.
fn library_motions(bar: f64, out: Option<&Path>) -> Result<Vec<Measured>> {
    let library = Library::builtin();
    let mut tracks: Vec<(String, PostureTrack)> = library
        .postures
        .iter()
        .map(|p| {
            (
                p.name.clone(),
                PostureTrack::holding(BodyPart::ALL.to_vec(), p.script.clone()),
            )
        })
        .collect();
    tracks.extend(
        library
            .actions
            .iter()
            .map(|a| (format!("{} (movement)", a.name), a.track(None, [0.0, 1.0]))),
    );
    if let Some(dir) = out {
        std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    }
    let mut rows = Vec::new();
    for (name, track) in tracks {
        let (motion, notes, frames) = from_rest(&track)?;
        for n in notes {
            eprintln!("note: {name}: {n}");
        }
        let made = &motion[frames];
        if let Some(dir) = out {
            let file: String = name
                .to_lowercase()
                .chars()
                .map(|c| if c.is_ascii_alphanumeric() { c } else { '-' })
                .collect();
            let options = FilmstripOptions {
                frames: 12,
                columns: 6,
                title: Some(name.clone()),
                view: View::ThreeQuarter,
                ..FilmstripOptions::default()
            };
            coma::render::write_filmstrip(&dir.join(format!("{file}.png")), made, &options)?;
            coma::motion_file::write_motion(
                &dir.join(format!("{file}.npy")),
                &coma::motion_file::MotionData::Joints(made.to_vec()),
                false,
            )?;
        }
        rows.push(Measured {
            measure: measure::measure(made, bar),
            whole_body: track.whole_body(),
            name,
            without: None,
        });
    }
    Ok(rows)
}

/// Where one posture track of a run's plan lies: the segment's index, whether it drives the
/// whole body, the frames it made in the laid motion, and the frames it covered in the
/// generated motion before any track was laid.
struct LaidSpan {
    segment: usize,
    whole_body: bool,
    frames: Range<usize>,
    generated: Range<usize>,
}

/// Where the posture tracks of a run's plan lie in its motion, in the order they are laid,
/// with the generated motion under them (joints with the features' final frame, no track
/// laid). The motion is laid again here, a track at a time, to follow how whole-body tracks
/// lengthen or shorten it (as `pipeline::lay_postures` does in one go); the last figure is
/// the length of the whole laid motion (joints, with the features' final frame).
fn posture_frames(
    model: &coma::model::MotionModel,
    plan: &coma::plan::Plan,
    tokens: &coma::model::tokens::MotionTokens,
) -> (Vec<LaidSpan>, Vec<Pose>, usize) {
    let features = block_on(pipeline::motion_features(model, plan, tokens)).0;
    let base = features_to_joints_with_final(&with_reference_bones(&features));
    let mut spans: Vec<(usize, TrackSpan)> = plan
        .segments
        .iter()
        .zip(pipeline::segment_ranges(plan, tokens))
        .enumerate()
        .filter_map(|(i, (s, frames))| {
            s.postures.as_ref().map(|track| {
                (
                    i,
                    TrackSpan {
                        frames: track.frames_within(frames),
                        track,
                    },
                )
            })
        })
        .collect();
    spans.sort_by_key(|(_, s)| s.frames.start);
    let only: Vec<TrackSpan> = spans.iter().map(|(_, s)| s.clone()).collect();
    let length = |k: usize| {
        lay_tracks(&base, &only[..k], Library::builtin_bridges())
            .0
            .len()
    };
    let mut out = Vec::new();
    let mut before = base.len();
    for (k, (segment, span)) in spans.iter().enumerate() {
        let after = length(k + 1);
        let shift = before as isize - base.len() as isize;
        // As `lay_tracks` places the span.
        let start = (span.frames.start as isize + shift).clamp(0, before as isize - 1) as usize;
        let end = ((span.frames.end as isize + shift).max(start as isize + 1) as usize).min(before);
        let frames = if span.track.whole_body() {
            let next = usize::from(end < before);
            start.saturating_sub(1)..(end + after + next).saturating_sub(before)
        } else {
            start..end
        };
        let generated = span.frames.start.min(base.len())..span.frames.end.min(base.len());
        out.push(LaidSpan {
            segment: *segment,
            whole_body: span.track.whole_body(),
            frames,
            generated,
        });
        before = after;
    }
    (out, base, before)
}

/// Runs every prompt of a set as `coma run` does (no LLM) and measures its posture tracks.
fn prompt_motions(args: &MotionsArgs, set: &Path, bar: f64) -> Result<(Vec<Measured>, usize)> {
    let prompts = coma::agents::planner::prompt_set::load(set)?;
    let session = crate::common::load_session(&args.models)?;
    let mut rows = Vec::new();
    let mut without = 0;
    for p in &prompts {
        let command = Command::Run {
            prompt: p.prompt.clone(),
            seed: args.seed,
            rounds: args.rounds,
            seconds: None,
            plan: None,
        };
        let outcome = block_on(session.execute(command, &Llm::<UreqTransport>::Off, &mut |_| {}))?;
        let Outcome::Run(run) = outcome else {
            bail!("the engine answered a run with something else");
        };
        if !run.plan.segments.iter().any(|s| s.postures.is_some()) {
            without += 1;
            eprintln!("no posture segment: {}", p.prompt);
            continue;
        }
        let joints = features_to_joints(&run.motion.features);
        let (spans, generated, laid) =
            posture_frames(session.model(), &run.plan, &run.motion.tokens);
        if laid != joints.len() + 1 {
            eprintln!(
                "note: '{}': the motion has {} frames, laying its postures again gave {}",
                p.prompt,
                joints.len(),
                laid.saturating_sub(1)
            );
        }
        for span in spans {
            let frames = span.frames.start.min(joints.len())..span.frames.end.min(joints.len());
            let s = &run.plan.segments[span.segment];
            let keys: Vec<&str> = s
                .postures
                .iter()
                .flat_map(|t| &t.keys)
                .filter_map(|k| k.script.name.as_deref())
                .collect();
            rows.push(Measured {
                name: format!(
                    "\"{}\" seg {} {}[{}] frames {}..{}",
                    p.prompt,
                    span.segment + 1,
                    if span.whole_body { "" } else { "on parts " },
                    keys.join(", "),
                    frames.start,
                    frames.end
                ),
                whole_body: span.whole_body,
                measure: measure::measure(&joints[frames], bar),
                without: (!span.whole_body)
                    .then(|| measure::measure(&generated[span.generated], bar)),
            });
        }
    }
    Ok((rows, without))
}

fn print_measured(rows: &[Measured], real: &RealReference, bar: f64) {
    println!(
        "  {:>6} {:>8} {:>10} {:>6} {:>12}  {:<30} {:>5}  motion",
        "frames", "skating", "lowest cm", "flight", "fastest m/s", "(joint at s)", "pass"
    );
    for r in rows {
        let m = &r.measure;
        let (fastest, at) = match &m.fastest {
            Some(f) => (
                format!("{:.2}", f.speed),
                format!("({} at {:.2} s)", f.joint_name(), f.frame as f64 / FPS),
            ),
            None => ("-".into(), String::new()),
        };
        println!(
            "  {:>6} {:>8.3} {:>10.1} {:>6} {:>12}  {:<30} {:>5}  {}",
            m.frames,
            m.skating,
            m.lowest_m * 100.0,
            m.flight_frames,
            fastest,
            at,
            if m.passes(real.skating) { "yes" } else { "NO" },
            r.name
        );
        if let Some(w) = &r.without {
            println!(
                "  {:>6} {:>8.3} {:>10.1} {:>6} {:>12}  {:<30} {:>5}    the generated motion \
                 under it, without the posture",
                w.frames,
                w.skating,
                w.lowest_m * 100.0,
                w.flight_frames,
                w.fastest.map_or("-".into(), |f| format!("{:.2}", f.speed)),
                "",
                if w.passes(real.skating) { "yes" } else { "NO" },
            );
        }
    }
    if rows.is_empty() {
        return;
    }
    let n = rows.len() as f64;
    let mean = rows.iter().map(|r| r.measure.skating).sum::<f64>() / n;
    let pooled = {
        let pairs: f64 = rows
            .iter()
            .map(|r| r.measure.frames.saturating_sub(1) as f64)
            .sum();
        rows.iter()
            .map(|r| r.measure.skating * r.measure.frames.saturating_sub(1) as f64)
            .sum::<f64>()
            / pairs.max(1.0)
    };
    let worst_skate = rows
        .iter()
        .max_by(|a, b| a.measure.skating.total_cmp(&b.measure.skating))
        .unwrap();
    let lowest = rows
        .iter()
        .min_by(|a, b| a.measure.lowest_m.total_cmp(&b.measure.lowest_m))
        .unwrap();
    let fastest = rows
        .iter()
        .filter_map(|r| r.measure.fastest.map(|f| (r, f)))
        .max_by(|a, b| a.1.speed.total_cmp(&b.1.speed));
    let over: usize = rows.iter().map(|r| r.measure.pairs_over).sum();
    let over_motions = rows.iter().filter(|r| r.measure.pairs_over > 0).count();
    let skating_over = rows
        .iter()
        .filter(|r| r.measure.skating > real.skating)
        .count();
    let under = rows
        .iter()
        .filter(|r| r.measure.lowest_m < -measure::MAX_BELOW_FLOOR_M)
        .count();
    println!(
        "  overall, {} motions: foot skating mean {mean:.3}, pooled over frames {pooled:.3} \
         (real {:.3}; {skating_over} motions above it, {:.0} %, against {:.0} % of the real \
         motions; worst {:.3}: {})",
        rows.len(),
        real.skating,
        100.0 * skating_over as f64 / rows.len().max(1) as f64,
        100.0 * real.skating_share_above,
        worst_skate.measure.skating,
        worst_skate.name
    );
    println!(
        "  lowest joint {:.1} cm ({}); {under} motions more than {:.0} cm below the floor",
        lowest.measure.lowest_m * 100.0,
        lowest.name,
        measure::MAX_BELOW_FLOOR_M * 100.0
    );
    if let Some((r, f)) = fastest {
        println!(
            "  fastest joint outside flight {:.2} m/s ({} at {:.2} s of {}); real 99th \
             percentile {bar:.2} m/s: {over} frame pairs in {over_motions} motions above it",
            f.speed,
            f.joint_name(),
            f.frame as f64 / FPS,
            r.name
        );
    }
    let under_rows: Vec<&Measure> = rows.iter().filter_map(|r| r.without.as_ref()).collect();
    if !under_rows.is_empty() {
        println!(
            "  the generated motion under them, without the postures: foot skating mean {:.3} \
             ({} of {} above the real {:.3})",
            under_rows.iter().map(|m| m.skating).sum::<f64>() / under_rows.len() as f64,
            under_rows
                .iter()
                .filter(|m| m.skating > real.skating)
                .count(),
            under_rows.len(),
            real.skating
        );
    }
    println!(
        "  {} of {} motions meet all three",
        rows.iter()
            .filter(|r| r.measure.passes(real.skating))
            .count(),
        rows.len()
    );
}

fn run_motions(args: MotionsArgs) -> Result<()> {
    let set = MotionSet::load(&args.data, Split::Test).with_context(|| {
        format!(
            "reading the test motions of {} (build them with `coma data build --bandai \
             ../shared/data/bandai-namco-bvh.tar.xz --out {}`)",
            args.data.display(),
            args.data.display()
        )
    })?;
    let real = measure::real_reference(&reference_motions(&set));
    let bar = real.p99_fastest;
    println!(
        "real test motions of {} ({} motions, {} frames): foot skating {:.3} (mean over \
         motions); lowest joint {:.1} cm; 99th percentile of the fastest joint's speed per \
         frame {:.2} m/s (outside flight {:.2}), of every joint's speed {:.2} m/s",
        args.data.display(),
        real.motions,
        real.frames,
        real.skating,
        real.lowest_m * 100.0,
        real.p99_fastest,
        real.p99_fastest_outside_flight,
        real.p99_joint
    );
    println!(
        "bars: foot skating <= {:.3}; no joint below {:.0} cm; no joint faster than {bar:.2} \
         m/s outside flight (no joint within {:.0} cm of the floor) and the frames next to it",
        real.skating,
        -measure::MAX_BELOW_FLOOR_M * 100.0,
        measure::FLIGHT_CLEARANCE_M * 100.0
    );
    println!();
    println!(
        "library motions (go stage from standing; postures held on the whole body, movements \
         once, forward):"
    );
    let library = library_motions(bar, args.out.as_deref())?;
    print_measured(&library, &real, bar);
    if let Some(set) = &args.prompts {
        println!();
        let (rows, without) = prompt_motions(&args, set, bar)?;
        println!(
            "posture tracks of the engine's runs of {} (seed {}, {} review rounds, no LLM; {} \
             prompts planned without one):",
            set.display(),
            args.seed,
            args.rounds,
            without
        );
        let (whole, parts): (Vec<Measured>, Vec<Measured>) =
            rows.into_iter().partition(|r| r.whole_body);
        println!(" posture segments (key poses on the whole body):");
        print_measured(&whole, &real, bar);
        println!(" postures held on parts over the generated motion:");
        print_measured(&parts, &real, bar);
    }
    Ok(())
}
