//! Checks of the posture solver that `coma posture check` prints and the tests assert: the
//! round trip (script → solved pose → the describer reads the constraints back) on random valid
//! scripts and on given ones, and a fuzz of random and mutated scripts that must give a message
//! or a pose, never a panic, a broken joint limit or a joint under the floor.

use super::script::{describe_pose, PostureScript};
use super::solver::{clamp_angles, imbalance_m, pose_of, rest_angles, solve, Angles, Solved};
use crate::posecodes::floor_height;
use crate::rng::Rng;
use crate::skeleton::Pose;
use serde::Serialize;

/// A solved pose may dip at most this far below the floor, metres (the acceptance line).
pub const FLOOR_TOLERANCE_M: f64 = 0.01;

/// The outcome of solving a set of scripts and reading them back.
#[derive(Clone, Debug, Default, Serialize)]
pub struct RoundTrip {
    /// Scripts solved.
    pub scripts: usize,
    /// Constraints in them.
    pub constraints: usize,
    /// Constraints the describer read back from the solved poses.
    pub read_back: usize,
    /// Scripts whose every constraint was read back.
    pub scripts_met: usize,
    /// Solved poses with an angle outside its joint limit (should be 0).
    pub limit_breaks: usize,
    /// Solved poses with a joint more than [`FLOOR_TOLERANCE_M`] below the floor (should be 0).
    pub below_floor: usize,
    /// Up to 20 misses: the script's name (or its number) and the constraint in words.
    pub misses: Vec<String>,
    /// Slowest and mean solve time, milliseconds (filled by callers that time it).
    pub mean_ms: f64,
}

impl RoundTrip {
    /// Share of constraints read back, 0–1.
    pub fn rate(&self) -> f64 {
        self.read_back as f64 / self.constraints.max(1) as f64
    }

    fn add(&mut self, label: &str, script: &PostureScript, start: Option<&Angles>) -> Solved {
        let solved = solve(script, start);
        self.scripts += 1;
        self.constraints += script.constraints.len();
        self.read_back += script.constraints.len() - solved.unmet.len();
        self.scripts_met += solved.unmet.is_empty() as usize;
        if clamp_angles(solved.angles) != solved.angles {
            self.limit_breaks += 1;
        }
        if floor_height(&[solved.pose]) < -FLOOR_TOLERANCE_M {
            self.below_floor += 1;
        }
        for c in &solved.unmet {
            if self.misses.len() < 20 {
                self.misses.push(format!("{label}: {c}"));
            }
        }
        solved
    }
}

/// Solves named scripts one after another from the rest pose and reads each back.
pub fn round_trip_scripts<'a>(
    scripts: impl IntoIterator<Item = (String, &'a PostureScript)>,
    now_ms: &dyn Fn() -> f64,
) -> RoundTrip {
    let mut report = RoundTrip::default();
    let start = now_ms();
    for (label, script) in scripts {
        report.add(&label, script, None);
    }
    report.mean_ms = (now_ms() - start) / report.scripts.max(1) as f64;
    report
}

/// Each pose's solve time of a timed round trip, and the solved poses with a non-finite
/// coordinate (should be none).
#[derive(Clone, Debug, Default, Serialize)]
pub struct PoseTimes {
    /// Milliseconds per pose, in the order solved.
    pub ms: Vec<f64>,
    /// Solved poses with a NaN or infinite coordinate.
    pub non_finite: usize,
}

impl PoseTimes {
    /// Mean milliseconds per pose.
    pub fn mean(&self) -> f64 {
        self.ms.iter().sum::<f64>() / self.ms.len().max(1) as f64
    }

    /// Median milliseconds per pose (the mean of the middle two for an even count).
    pub fn median(&self) -> f64 {
        let mut sorted = self.ms.clone();
        sorted.sort_by(f64::total_cmp);
        match sorted.len() {
            0 => 0.0,
            n if n % 2 == 1 => sorted[n / 2],
            n => 0.5 * (sorted[n / 2 - 1] + sorted[n / 2]),
        }
    }

    /// Slowest pose, milliseconds.
    pub fn max(&self) -> f64 {
        self.ms.iter().copied().fold(0.0, f64::max)
    }
}

/// As [`round_trip_scripts`], timing each pose on its own (for the solver's speed, natively and
/// in the browser: `web/tests/posture_speed.rs`). `now_ms` is any millisecond clock.
pub fn round_trip_timed<'a>(
    scripts: impl IntoIterator<Item = (String, &'a PostureScript)>,
    now_ms: &dyn Fn() -> f64,
) -> (RoundTrip, PoseTimes) {
    let mut report = RoundTrip::default();
    let mut times = PoseTimes::default();
    for (label, script) in scripts {
        let start = now_ms();
        let solved = report.add(&label, script, None);
        times.ms.push(now_ms() - start);
        if !solved.pose.iter().flatten().all(|v| v.is_finite()) {
            times.non_finite += 1;
        }
    }
    report.mean_ms = times.mean();
    (report, times)
}

/// A random pose that stands still: angles drawn near the rest pose (or anywhere in their
/// limits, for a third of them), kept when the centre of mass is over the support.
pub fn random_pose(rng: &mut Rng) -> (Angles, Pose) {
    let limits = super::solver::LIMITS_DEG;
    let rest = rest_angles();
    let mut fallback = None;
    for _ in 0..50 {
        let mut a = rest;
        for (i, v) in a.iter_mut().enumerate() {
            let [lo, hi] = limits[i].map(f64::to_radians);
            *v = if rng.below(3) == 0 {
                lo + (hi - lo) * rng.uniform() as f64
            } else {
                *v + (hi - lo) * 0.25 * rng.normal() as f64
            };
        }
        let a = clamp_angles(a);
        let pose = pose_of(&a);
        if imbalance_m(&pose) < 0.02 {
            return (a, pose);
        }
        fallback.get_or_insert((a, pose));
    }
    fallback.unwrap_or_else(|| (rest, pose_of(&rest)))
}

/// A random valid script: 3 to 10 of the constraints the describer reads off a random standing
/// pose, so that some pose meets them all.
pub fn random_script(rng: &mut Rng) -> PostureScript {
    let (_, pose) = random_pose(rng);
    let mut all = describe_pose(&pose, 0.0);
    rng.shuffle(&mut all);
    let k = 3 + rng.below(8);
    all.truncate(k);
    PostureScript {
        name: None,
        hold: 0.5,
        constraints: all,
    }
    .check()
    .expect("constraints read off one pose agree")
}

/// `n` random valid scripts from `seed`: the ones [`round_trip_random`] solves.
pub fn random_scripts(n: usize, seed: u64) -> Vec<PostureScript> {
    let mut rng = Rng::new(seed);
    (0..n).map(|_| random_script(&mut rng)).collect()
}

/// Solves `n` random valid scripts (seeded) from the rest pose and reads them back.
pub fn round_trip_random(n: usize, seed: u64, now_ms: &dyn Fn() -> f64) -> RoundTrip {
    let scripts = random_scripts(n, seed);
    round_trip_scripts(
        scripts
            .iter()
            .enumerate()
            .map(|(i, s)| (format!("random script {}", i + 1), s)),
        now_ms,
    )
}

/// What the fuzz saw.
#[derive(Clone, Debug, Default, Serialize)]
pub struct Fuzz {
    /// Inputs tried.
    pub inputs: usize,
    /// Inputs refused with a message.
    pub refused: usize,
    /// Inputs accepted and solved.
    pub solved: usize,
    /// Refusals with an empty message (should be 0).
    pub silent_refusals: usize,
    /// Solved poses with a non-finite coordinate, a broken limit or a joint under the floor
    /// (should be 0).
    pub bad_poses: usize,
    /// A few refusal messages, to show what a person or an LLM reads.
    pub sample_messages: Vec<String>,
}

const WORDS: [&str; 40] = [
    "bend",
    "distance",
    "relation",
    "orientation",
    "contact",
    "lean",
    "twist",
    "level",
    "joint",
    "is",
    "a",
    "b",
    "limb",
    "point",
    "on_ground",
    "left_elbow",
    "right_knee",
    "left_hand",
    "head",
    "pelvis",
    "straight",
    "completely_bent",
    "close",
    "wide",
    "above",
    "behind",
    "left_of",
    "vertical",
    "horizontal",
    "forward",
    "upright",
    "none",
    "kneeling",
    "lying",
    "sitting",
    "left_thigh",
    "torso",
    "left_foot",
    "bent",
    "banana",
];

fn random_value(rng: &mut Rng, depth: usize) -> serde_json::Value {
    use serde_json::Value;
    match rng.below(if depth > 2 { 5 } else { 7 }) {
        0 => Value::Null,
        1 => Value::Bool(rng.below(2) == 0),
        2 => serde_json::json!((rng.normal() as f64) * 10f64.powi(rng.below(8) as i32 - 2)),
        3 | 4 => Value::String(WORDS[rng.below(WORDS.len())].to_string()),
        5 => Value::Array(
            (0..rng.below(5))
                .map(|_| random_value(rng, depth + 1))
                .collect(),
        ),
        _ => Value::Object(
            (0..rng.below(5))
                .map(|_| {
                    (
                        WORDS[rng.below(WORDS.len())].to_string(),
                        random_value(rng, depth + 1),
                    )
                })
                .collect(),
        ),
    }
}

/// A valid script's JSON with one to three random edits: a word swapped, a field dropped or
/// added, a value replaced by junk, a constraint duplicated with another value, or constraints
/// taken from another pose (well-formed, but possibly contradictory or unreachable together).
fn mutated(rng: &mut Rng) -> serde_json::Value {
    let mut script = random_script(rng);
    if rng.below(2) == 0 {
        let (_, other) = random_pose(rng);
        let mut foreign = describe_pose(&other, 0.0);
        rng.shuffle(&mut foreign);
        for c in foreign.into_iter().take(1 + rng.below(4)) {
            let i = rng.below(script.constraints.len());
            script.constraints[i] = c;
        }
        return serde_json::to_value(script).expect("a script serialises");
    }
    let mut v = serde_json::to_value(script).expect("a script serialises");
    for _ in 0..1 + rng.below(3) {
        let Some(list) = v["constraints"].as_array_mut().filter(|l| !l.is_empty()) else {
            break;
        };
        let i = rng.below(list.len());
        match rng.below(6) {
            0 | 1 => {
                let Some(c) = list[i].as_object_mut() else {
                    continue;
                };
                let keys: Vec<String> = c.keys().cloned().collect();
                if keys.is_empty() {
                    continue;
                }
                let k = keys[rng.below(keys.len())].clone();
                if rng.below(2) == 0 {
                    c.insert(k, WORDS[rng.below(WORDS.len())].into());
                } else {
                    c.remove(&k);
                }
            }
            2 => {
                let mut copy = list[i].clone();
                if let Some(obj) = copy.as_object_mut() {
                    let keys: Vec<String> = obj.keys().cloned().collect();
                    if !keys.is_empty() {
                        let k = &keys[rng.below(keys.len())];
                        obj.insert(k.clone(), WORDS[rng.below(WORDS.len())].into());
                    }
                }
                list.push(copy);
            }
            3 => list[i] = random_value(rng, 1),
            4 => v["hold"] = random_value(rng, 2),
            _ => {
                let extra = random_value(rng, 1);
                v.as_object_mut()
                    .expect("a script is an object")
                    .insert(WORDS[rng.below(WORDS.len())].to_string(), extra);
            }
        }
    }
    v
}

/// Feeds `n` inputs (half random JSON, half mutated valid scripts) to the parser and solves
/// whatever it accepts.
pub fn fuzz(n: usize, seed: u64) -> Fuzz {
    let mut rng = Rng::new(seed);
    let mut report = Fuzz::default();
    for k in 0..n {
        let value = if k % 2 == 0 {
            random_value(&mut rng, 0)
        } else {
            mutated(&mut rng)
        };
        report.inputs += 1;
        match PostureScript::from_value(value) {
            Err(e) => {
                report.refused += 1;
                let message = e.to_string();
                if message.trim().is_empty() {
                    report.silent_refusals += 1;
                }
                if report.sample_messages.len() < 8 && rng.below(50) == 0 {
                    report.sample_messages.push(message);
                }
            }
            Ok(script) => {
                report.solved += 1;
                let solved = solve(&script, None);
                let finite = solved.pose.iter().flatten().all(|v| v.is_finite());
                if !finite
                    || clamp_angles(solved.angles) != solved.angles
                    || floor_height(&[solved.pose]) < -FLOOR_TOLERANCE_M
                {
                    report.bad_poses += 1;
                }
            }
        }
    }
    report
}
