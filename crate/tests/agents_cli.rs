//! `coma plan`, `coma run` and `coma traj` as a user runs them.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn coma() -> Command {
    Command::new(env!("CARGO_BIN_EXE_coma"))
}

fn repo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

fn stdout(out: &Output) -> String {
    assert!(
        out.status.success(),
        "{}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8_lossy(&out.stdout).into_owned()
}

const PROMPT: &str = "A person walks forward waving the left hand, then turns right and bows";

#[test]
fn plan_prints_the_offline_plan_as_json() {
    let out = coma()
        .args(["plan", PROMPT, "--json", "--models"])
        .arg(repo().join("static/models"))
        .output()
        .unwrap();
    let plan: serde_json::Value = serde_json::from_str(&stdout(&out)).unwrap();
    let segments = plan["segments"].as_array().unwrap();
    assert_eq!(segments.len(), 3, "{plan:#}");
    assert_eq!(
        segments[0]["parts"]["left_arm"],
        "a person waves the left hand"
    );
    assert_eq!(segments[2]["base"], "a person bows");
    assert_eq!(plan["planner"]["kind"], "offline");
}

#[test]
fn plan_scores_the_prompt_set() {
    let out = coma()
        .args(["plan", "--json", "--prompts"])
        .arg(repo().join("eval/prompts.json"))
        .arg("--models")
        .arg(repo().join("static/models"))
        .output()
        .unwrap();
    let report: serde_json::Value = serde_json::from_str(&stdout(&out)).unwrap();
    assert!(report["prompts"].as_u64().unwrap() >= 30);
    assert!(
        report["segment_rate"].as_f64().unwrap() >= 0.9,
        "{report:#}"
    );
}

#[test]
fn plan_scores_the_timeline_set_clause_by_clause() {
    let set = repo().join("crate/tests/fixtures/timeline_small.json");
    let run = |json: bool| {
        let mut cmd = coma();
        cmd.args(["plan", "--timeline-set"])
            .arg(&set)
            .arg("--models")
            .arg(repo().join("static/models"));
        if json {
            cmd.arg("--json");
        }
        stdout(&cmd.output().unwrap())
    };
    let report: serde_json::Value = serde_json::from_str(&run(true)).unwrap();
    assert_eq!(report["prompts"], 3, "{report:#}");
    assert_eq!(report["clauses"], 8, "{report:#}");
    let results = report["results"].as_array().unwrap();
    assert_eq!(results.len(), 3);
    // The README's own kind of prompt: both clauses on the body track, in order.
    for clause in results[0]["clauses"].as_array().unwrap() {
        assert_eq!(clause["correct"], true, "{:#}", results[0]);
    }
    let count = |key: &str| report[key].as_u64().unwrap();
    let clauses = results
        .iter()
        .flat_map(|r| r["clauses"].as_array().unwrap());
    let correct = clauses.clone().filter(|c| c["correct"] == true).count() as u64;
    let lost = clauses
        .filter(|c| {
            c["misses"]
                .as_array()
                .unwrap()
                .iter()
                .any(|m| m["kind"] == "lost")
        })
        .count() as u64;
    assert_eq!(count("correct"), correct);
    assert_eq!(count("silently_lost"), lost);
    assert!(report["planner_seconds"].as_f64().unwrap() > 0.0);
    let text = run(false);
    for line in [
        "clauses placed correctly: ",
        "clauses silently lost: ",
        "side swaps: ",
        "prompts with every clause placed correctly: ",
        "planner time: ",
    ] {
        assert!(text.contains(line), "{text}");
    }
    assert!(!text.contains("✗ walk-bow"), "{text}");
    // A clause whose words are not in its prompt is a bad file, named as such.
    let dir = tempfile::tempdir().unwrap();
    let bad = dir.path().join("bad.json");
    let written = std::fs::read_to_string(&set)
        .unwrap()
        .replace("\"text\": \"bows\"", "\"text\": \"curtsies\"");
    std::fs::write(&bad, written).unwrap();
    let out = coma()
        .args(["plan", "--timeline-set"])
        .arg(&bad)
        .output()
        .unwrap();
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("prompt \"walk-bow\", clause 1 (\"curtsies\"): its text is not in the prompt"),
        "{err}"
    );
}

#[test]
fn traj_draws_a_clockwise_circle_that_closes() {
    let dir = tempfile::tempdir().unwrap();
    let png = dir.path().join("circle.png");
    let out = coma()
        .args(["traj", "walk in a circle clockwise", "--out"])
        .arg(&png)
        .output()
        .unwrap();
    let text = stdout(&out);
    assert!(text.contains("clockwise, closure error"), "{text}");
    assert!(!text.contains("counter-clockwise, closure"), "{text}");
    let closure: f64 = text
        .split("closure error ")
        .nth(1)
        .and_then(|s| s.split(' ').next())
        .and_then(|s| s.parse().ok())
        .unwrap();
    assert!(closure < 0.05, "{text}");
    assert_eq!(&std::fs::read(&png).unwrap()[..4], b"\x89PNG");
}

#[test]
fn traj_refuses_code_and_unknown_shapes() {
    let dir = tempfile::tempdir().unwrap();
    for (arg, message) in [
        ("system('ls'); t; 0; 1", "unknown name"),
        ("sin(t); t; 1; 0", "range"),
        ("dance like nobody watches", "no path shape"),
    ] {
        let out = coma()
            .args(["traj", arg, "--out"])
            .arg(dir.path().join("x.png"))
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success(), "{arg}");
        assert!(err.contains(message), "{arg}: {err}");
        assert!(!err.contains("panicked"), "{err}");
    }
}

#[test]
fn run_lays_a_clockwise_circle_on_the_root_and_writes_files() {
    // Random weights of the default sizes: this checks the plumbing of the loop (plan,
    // generate, blend, path, files), not the motion's quality.
    let dir = tempfile::tempdir().unwrap();
    let models = dir.path().join("models");
    stdout(
        &coma()
            .args(["export", "random", "--data"])
            .arg(repo().join("../shared/data/humanml3d-reference"))
            .arg("--out")
            .arg(&models)
            .current_dir(repo())
            .output()
            .unwrap(),
    );
    for f in [
        "minilm-vocab.txt",
        "minilm-words.i8",
        "minilm-encoder.bpk",
        "vocabulary.json",
    ] {
        std::fs::copy(repo().join("static/models").join(f), models.join(f)).unwrap();
    }
    let bvh = dir.path().join("run.bvh");
    let out = coma()
        .args([
            "run",
            "a person walks in a circle clockwise",
            "--rounds",
            "1",
            "--json",
        ])
        .arg("--models")
        .arg(&models)
        .arg("--out")
        .arg(&bvh)
        .output()
        .unwrap();
    let run: serde_json::Value = serde_json::from_str(&stdout(&out)).unwrap();
    let circle = &run["paths"][0]["circle"];
    assert_eq!(circle["turned_clockwise"], true, "{run:#}");
    assert!(
        circle["closure_error_m"].as_f64().unwrap() < 0.3,
        "{circle}"
    );
    assert!(
        circle["mean_radius_error_m"].as_f64().unwrap() < 0.1,
        "{circle}"
    );
    assert!(run["notes"]
        .as_array()
        .unwrap()
        .iter()
        .any(|n| n.as_str().unwrap().contains("not reviewed")));
    assert!(std::fs::read_to_string(&bvh)
        .unwrap()
        .starts_with("HIERARCHY"));
}
