//! A whole evaluation (`coma eval`): the protocol's rows on the test split (real motions, a
//! retrieval baseline, SPAM, SPAM with the review loop), the control probes of the motions
//! SPAM generates, and the agents' figures, gathered into one [`EvalReport`].

use super::agents::{
    circle_probe, planner_figures, review_figures, timeline_figures, AgentFigures,
};
use super::probes::{
    action, edit_locality, left_right, left_right_legs, quantile, ACTIONS, LOCALITY_BASE,
    LOCALITY_EDIT, LOCALITY_SEEDS,
};
use super::protocol::{Motions, Protocol, ProtocolOptions};
use super::references::{walk_to_bow, ActionReference};
use super::report::{ActionFigure, EvalReport, JoinSpeeds, Probes};
use crate::dataset::motions::MotionSet;
use crate::dataset::Split;
use crate::model::evaluator::Evaluator;
use crate::model::generate::SamplingOptions;
use crate::model::MotionModel;
use crate::session::{read_vocabulary, Session, VOCABULARY_FILE};
use crate::text::minilm::SentenceEncoder;
use anyhow::Result;
use burn::tensor::Device;
use std::path::{Path, PathBuf};

/// What `coma eval` measures of the agents.
#[derive(Clone, Debug)]
pub struct AgentEvalOptions {
    /// The prompt set (e.g. `eval/prompts.json`): prompts with the segments, body-part edits
    /// and paths their motions should have, for the planner and the review loop.
    pub prompts: PathBuf,
    /// The timeline prompt set (e.g. `eval/timeline_prompts.json`): prompts annotated clause
    /// by clause, for the planner.
    pub timeline_prompts: PathBuf,
    /// Review rounds (K) per segment of a reviewed motion; 0 skips the review loop.
    pub review_rounds: usize,
    /// Repetitions of the protocol the spam_review row takes part in.
    pub review_repeats: usize,
}

/// Everything one evaluation needs: where the evaluator, the dataset and SPAM are, and how
/// much to measure.
#[derive(Clone, Debug)]
pub struct EvalOptions<'a> {
    /// Folder with `evaluator.json`, `evaluator.bpk` and the sentence encoder: the
    /// text–motion evaluator that scores every motion.
    pub evaluator: &'a Path,
    /// Dataset whose `split` is measured (and whose training split the retrieval baseline
    /// answers from).
    pub data: &'a Path,
    /// The split measured: the test split for the report, the validation split to choose
    /// sampling options without looking at the test motions.
    pub split: Split,
    /// How SPAM's rows sample (guidance, temperature, top-k); the seeds are the protocol's.
    pub sampling: SamplingOptions,
    /// SPAM's model folder; without it only the real and retrieval rows and the planner are
    /// measured.
    pub spam: Option<&'a Path>,
    pub protocol: ProtocolOptions,
    /// Seeds per prompt of the left/right probe.
    pub probe_seeds: u64,
    pub agents: AgentEvalOptions,
    /// The command line the report says made it.
    pub command: String,
}

/// The planner on the prompt set; with SPAM, the review loop over it and the circle probe.
/// Progress lines go to `log`.
pub fn evaluate_agents(
    session: Option<&Session>,
    options: &AgentEvalOptions,
    log: &dyn Fn(&str),
) -> Result<AgentFigures> {
    let prompts = crate::agents::planner::prompt_set::load(&options.prompts)?;
    let mut figures = AgentFigures {
        planner: Some(planner_figures(
            &prompts,
            session.and_then(Session::vocabulary),
            None,
        )),
        ..Default::default()
    };
    if let Some(session) = session {
        log("agents: the timeline prompt set");
        figures.timeline = Some((
            options.timeline_prompts.display().to_string(),
            timeline_figures(session, &options.timeline_prompts)?,
        ));
        log("agents: the circle probe");
        figures.circle = circle_probe(session, 0)?;
        if options.review_rounds > 0 {
            figures.review = Some(review_figures(
                session,
                &prompts,
                options.review_rounds,
                0,
                log,
            )?);
        }
    }
    Ok(figures)
}

/// Length of the left/right probes' generated motions, seconds: room for a raise, a wave or a
/// kick and its return.
const PROBE_SECONDS: f64 = 4.0;

/// The action probes whose action `train` shows, each over `seeds` seeds at the default
/// sampling options and the training performances' median length, against them.
fn action_figures(generator: &MotionModel, train: &MotionSet, seeds: u64) -> Vec<ActionFigure> {
    let options = SamplingOptions::default();
    ACTIONS
        .iter()
        .filter_map(|probe| {
            let real = ActionReference::of(train, probe)?;
            let report = action(
                generator,
                probe,
                seeds,
                real.seconds,
                &options,
                &[options.base_guidance],
                real.p10,
            )
            .pop()?;
            Some(ActionFigure {
                probe: probe.name.to_string(),
                prompt: probe.prompt.to_string(),
                measure: probe.measure_name.to_string(),
                unit: probe.unit.to_string(),
                median: quantile(report.values.clone(), 0.5),
                reaching: report.reaching,
                seeds: report.values.len(),
                seconds: real.seconds,
                real,
            })
        })
        .collect()
}

/// `coma eval`: the protocol's rows and the probes (with SPAM), and the agents' figures, as
/// the report `EVAL.md` and `eval.json` are made from. Progress lines go to `log`.
pub fn evaluate(options: &EvalOptions, log: &dyn Fn(&str)) -> Result<EvalReport> {
    let started = std::time::Instant::now();
    let device = Device::flex();
    let (evaluator, config) = Evaluator::load(options.evaluator, &device)?;
    let evaluator_id =
        crate::model::model_id_of_dir(options.evaluator, &["evaluator.json", "evaluator.bpk"])?;
    let text = SentenceEncoder::from_dir(options.evaluator, &device)?;
    let test = MotionSet::load(options.data, options.split)?;
    let train = MotionSet::load(options.data, Split::Train)?;
    let mut distinct: Vec<&str> = test
        .items
        .iter()
        .chain(&train.items)
        .flat_map(|i| i.captions.iter().map(String::as_str))
        .collect();
    distinct.sort_unstable();
    distinct.dedup();
    let mut sentences = std::collections::HashMap::new();
    for chunk in distinct.chunks(64) {
        for (c, e) in chunk.iter().zip(text.encode(chunk)) {
            sentences.insert(c.to_string(), e);
        }
    }
    log(&format!("embedded {} distinct captions", sentences.len()));
    // SPAM runs in the engine, with this evaluator as the review loop's judge and the
    // model's vocabulary, so the built-in planner plans as it does in the page and the CLI.
    let session = options
        .spam
        .map(|dir| MotionModel::load(dir, &device).map(|model| (dir, model)))
        .transpose()?
        .map(|(dir, model)| {
            let judge = Ok((evaluator.clone(), config.clone()));
            let vocabulary = read_vocabulary(&dir.join(VOCABULARY_FILE));
            Session::new(model, judge, vocabulary).0
        });
    let spam = session.as_ref().map(Session::model);
    if let (Some(model), Some(dir)) = (spam, options.spam) {
        model
            .spam
            .check_sampling(&options.sampling)
            .map_err(|e| anyhow::anyhow!("{}: {e}", dir.display()))?;
    }
    let agent_options = &options.agents;
    let mut sources = vec![("real", Motions::Real), ("retrieval", Motions::Retrieval)];
    if let (Some(session), Some(model)) = (&session, spam) {
        sources.push((
            "spam_decoded",
            Motions::SpamDecoded(&model.spam, &options.sampling),
        ));
        sources.push(("spam", Motions::Spam(&model.spam, &options.sampling)));
        if agent_options.review_rounds > 0 {
            sources.push((
                "spam_review",
                Motions::ReviewedSpam {
                    session,
                    rounds: agent_options.review_rounds,
                    repeats: agent_options.review_repeats,
                },
            ));
        }
    }
    let protocol = Protocol {
        evaluator: &evaluator,
        config: &config,
        device: &device,
        test: &test,
        train: &train,
        sentences: &sentences,
    };
    let rows = protocol.run(&sources, &options.protocol, log)?;
    let mut probes = Probes::default();
    if let Some(generator) = spam {
        let probe_seeds = options.probe_seeds;
        log(&format!(
            "probes: left/right over {probe_seeds} seeds a prompt"
        ));
        let lr = left_right(generator, probe_seeds, PROBE_SECONDS);
        probes.left_right_rate = Some(lr.rate);
        probes.left_right = lr.prompts;
        let locality = edit_locality(generator, LOCALITY_BASE, LOCALITY_EDIT, 0..LOCALITY_SEEDS);
        probes.edit_leg_change_cm = Some(locality.leg_change_cm);
        probes.edit_left_wrist_gain_cm = Some(locality.left_wrist_rise_gain_cm);
        let join = walk_to_bow(generator, &test, 0);
        probes.join_speeds = Some(JoinSpeeds {
            root: join.join_root_speed,
            joint: join.join_joint_speed,
            p99_root: join.p99_root_speed,
            p99_joint: join.p99_joint_speed,
        });
        log(&format!(
            "probes: left/right kicks and actions over {probe_seeds} seeds"
        ));
        probes.left_right_legs = Some(left_right_legs(generator, probe_seeds, PROBE_SECONDS));
        probes.actions = action_figures(generator, &train, probe_seeds);
    }
    let agents = evaluate_agents(session.as_ref(), agent_options, log)?;
    Ok(EvalReport {
        agents: Some(serde_json::to_value(&agents)?),
        agents_markdown: agents.markdown(),
        command: options.command.clone(),
        evaluator_id,
        spam_id: spam.map(|m| m.id.clone()),
        split: options.split.name().to_string(),
        prior: spam
            .and_then(|m| m.spam.prior.as_ref())
            .map(|p| options.sampling.prior.unwrap_or(p.options))
            .filter(|p| p.keep > 0.0),
        test_motions: test.items.iter().filter(|i| !i.captions.is_empty()).count(),
        options: options.protocol.clone(),
        rows,
        probes,
        seconds: started.elapsed().as_secs_f64(),
    })
}
