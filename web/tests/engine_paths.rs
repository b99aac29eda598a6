//! One engine behind the page and the command line: the same prompt, seed and backend (the
//! CPU) give the same plan and the same tokens through the page's worker path (its messages
//! and dispatch, called natively) and through `coma run`.
#![cfg(not(target_arch = "wasm32"))]

use coma::agents::llm::{HttpReply, HttpRequest, Transport, TransportError};
use coma::executor::block_on;
use coma::model::tokens::MotionTokens;
use coma::plan::Plan;
use coma::session::{Command, Outcome, Progress, Session};
use coma_web::dispatch;
use coma_web::messages::{from_json, to_json, Reply, Request};
use std::path::{Path, PathBuf};

/// No LLM is configured in this test, so no request is ever sent.
struct NoServer;

impl Transport for NoServer {
    async fn post(&self, _: HttpRequest<'_>) -> Result<HttpReply, TransportError> {
        Err(TransportError::Network("no server in this test".into()))
    }

    async fn sleep(&self, _: std::time::Duration) {}
}

fn repo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .unwrap()
        .into()
}

/// The `coma` binary beside this test's own (`cargo test --workspace` builds it).
fn coma_binary() -> PathBuf {
    let exe = std::env::current_exe().unwrap();
    let dir = exe.parent().unwrap().parent().unwrap();
    let bin = dir.join("coma");
    assert!(
        bin.exists(),
        "no coma binary at {}: run `cargo test --workspace` (or build -p coma) first",
        bin.display()
    );
    bin
}

#[test]
fn the_worker_path_and_the_command_line_plan_and_generate_the_same() {
    let prompt = "a person walks forward, then waves the left hand";
    let models = repo().join("static/models");

    // The page's path: the request as JSON, read as the worker reads it, the engine through
    // the worker's dispatch, every reply through JSON as the page reads it.
    let (session, missing) = Session::load(&models, &burn::tensor::Device::flex()).unwrap();
    assert!(missing.is_empty(), "{missing:?}");
    let request = to_json(&Request::Execute {
        command: Box::new(Command::Run {
            prompt: prompt.into(),
            seed: 4,
            rounds: 1,
            seconds: None,
            plan: None,
        }),
        llm: None,
    });
    let Ok(Request::Execute { command, llm }) = from_json::<Request>(&request) else {
        panic!("{request}")
    };
    let mut progress = Vec::new();
    let reply = block_on(dispatch::execute::<NoServer>(
        &session,
        *command,
        llm,
        |_| Err("no LLM in this test".into()),
        &mut |reply| progress.push(from_json::<Reply>(&to_json(&reply)).unwrap()),
        &|| 0.0,
    ));
    let Ok(Reply::Done {
        outcome: Outcome::Run(page),
        ..
    }) = from_json::<Reply>(&to_json(&reply))
    else {
        panic!("{reply:?}")
    };
    let planned = progress.iter().find_map(|r| match r {
        Reply::Progress {
            progress: Progress::Planned { plan },
        } => Some(plan.clone()),
        _ => None,
    });
    assert_eq!(planned.as_ref(), Some(&page.plan));
    assert_eq!(page.plan.segments.len(), 2);

    // The command line's path.
    let out = std::process::Command::new(coma_binary())
        .args([
            "run", prompt, "--seed", "4", "--rounds", "1", "--json", "--models",
        ])
        .arg(&models)
        .current_dir(repo())
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let cli: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let plan: Plan = serde_json::from_value(cli["plan"].clone()).unwrap();
    let tokens: MotionTokens = serde_json::from_value(cli["tokens"].clone()).unwrap();
    assert_eq!(plan, page.plan);
    assert_eq!(tokens, page.motion.tokens);
    assert_eq!(cli["frames"], page.motion.joints.len());
}
