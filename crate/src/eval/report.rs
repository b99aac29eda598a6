//! The evaluation report: `EVAL.md` for people and `eval.json` for programs, with the command
//! that made them and the ids of the weights measured.

use super::protocol::{markdown_table, ProtocolOptions, Row};
use std::collections::BTreeMap;

/// Rows in the order the tables show them.
pub const ROW_ORDER: [&str; 5] = ["real", "retrieval", "spam_decoded", "spam", "spam_review"];

/// Control probes of the model (absent when no SPAM model was measured).
#[derive(Clone, Debug, Default, serde::Serialize)]
pub struct Probes {
    /// Share of raise/wave samples where the asked wrist ends higher than the other.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub left_right_rate: Option<f64>,
    /// Per prompt: (prompt, correct, samples).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub left_right: Vec<(String, usize, usize)>,
    /// Mean leg-joint displacement after a left-arm edit of a walk, cm.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub edit_leg_change_cm: Option<f64>,
    /// How much higher the left wrist rises after that edit, cm.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub edit_left_wrist_gain_cm: Option<f64>,
    /// Fastest root and joint speeds at a blend join, and the 99th percentiles of real
    /// motion, m/s.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub join_speeds: Option<JoinSpeeds>,
    /// Left/right kicks: how often the asked ankle rises higher than the other.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub left_right_legs: Option<super::probes::LeftRightReport>,
    /// The action probes whose action the training split shows (squat, jump, …).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub actions: Vec<ActionFigure>,
}

/// How much of an action SPAM's motions perform against the training split's own
/// performances of it, by one of [`super::probes::ACTIONS`].
#[derive(Clone, Debug, serde::Serialize)]
pub struct ActionFigure {
    pub probe: String,
    pub prompt: String,
    /// What is measured, and its unit (metres, m/s, degrees).
    pub measure: String,
    pub unit: String,
    pub real: super::references::ActionReference,
    /// Median of the generated motions' measures.
    pub median: f64,
    /// Share of seeds whose motion reaches the real 10th percentile.
    pub reaching: f64,
    pub seeds: usize,
    /// Length of each generated motion, seconds.
    pub seconds: f64,
}

/// Speeds at a join against real motion.
#[derive(Clone, Copy, Debug, serde::Serialize)]
pub struct JoinSpeeds {
    pub root: f64,
    pub joint: f64,
    pub p99_root: f64,
    pub p99_joint: f64,
}

/// Everything `coma eval` measured.
#[derive(Clone, Debug, serde::Serialize)]
pub struct EvalReport {
    /// The command that produced the report.
    pub command: String,
    /// Id of the evaluator's weights and of the SPAM model (see `model::model_id`).
    pub evaluator_id: String,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub spam_id: Option<String>,
    /// The split measured (`test` for the report of record, `val` to tune on).
    pub split: String,
    /// How SPAM's rows used its retrieval prior; absent when the model has none or it was
    /// turned off.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub prior: Option<crate::model::prior::PriorOptions>,
    /// Captioned motions in that split.
    pub test_motions: usize,
    pub options: ProtocolOptions,
    pub rows: BTreeMap<String, Row>,
    pub probes: Probes,
    /// The planner, the review loop and the trajectory editor (native builds measure them).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub agents: Option<serde_json::Value>,
    /// The same figures, as markdown (made where they are measured).
    #[serde(skip)]
    pub agents_markdown: String,
    /// Wall-clock seconds the evaluation took.
    pub seconds: f64,
}

fn describe(name: &str) -> &'static str {
    match name {
        "real" => "the test motions themselves",
        "retrieval" => {
            "the training motion whose caption is nearest (MiniLM cosine) to the test caption"
        }
        "spam_decoded" => "SPAM, one shot, a motion of the test motion's length from the caption, as the VQ-VAE decodes it (before the engine's clean-up)",
        "spam" => "the same motions, measured as the engine hands them out (on the reference skeleton, feet planted)",
        "spam_review" => {
            "the same, then reviewed (up to K rounds, no LLM) with the evaluator as judge; the \
             judge is the evaluator that measures, so R-precision and MM-Dist favour this row \
             by construction; no multimodality (ten reviewed motions a caption)"
        }
        _ => "",
    }
}

impl EvalReport {
    /// `eval.json`: `{"rows": {...}, "probes": {...}, ...}`.
    pub fn json(&self) -> String {
        serde_json::to_string_pretty(self).expect("the report serialises")
    }

    /// `EVAL.md`.
    pub fn markdown(&self) -> String {
        let o = &self.options;
        let mut md = format!(
            "# Evaluation\n\nMade by `{}` in {:.0} s. Evaluator `{}`{}.\n\n",
            self.command,
            self.seconds,
            self.evaluator_id,
            self.spam_id
                .as_ref()
                .map_or(String::new(), |id| format!(", SPAM model `{id}`"))
        );
        md.push_str(&format!(
            "Protocol: the {} split ({} captioned motions); per repetition {} motions, each with one of its captions drawn at random, R-precision in batches of 32, FID against all its motions, diversity over {} pairs, multimodality over {} captions × {} samples ({} pairs each); {} repetitions, mean ± 95 % interval. Embeddings are the evaluator's unit vectors, so distances lie in [0, 2].\n\n",
            self.split,
            self.test_motions,
            o.motions.min(self.test_motions) / super::protocol::BATCH * super::protocol::BATCH,
            o.diversity_pairs,
            o.multimodality_texts,
            o.multimodality_samples,
            o.multimodality_pairs,
            o.repeats,
        ));
        md.push_str("## Text-to-motion metrics\n\n");
        md.push_str(&markdown_table(&self.rows, &ROW_ORDER));
        md.push('\n');
        for (name, row) in ROW_ORDER
            .iter()
            .filter_map(|n| self.rows.get(*n).map(|r| (n, r)))
        {
            let part = if row.repeats < o.repeats {
                format!(
                    " (measured on the first {} of the {} repetitions)",
                    row.repeats, o.repeats
                )
            } else {
                String::new()
            };
            md.push_str(&format!("- **{name}**: {}{part}\n", describe(name)));
        }
        if let Some(prior) = &self.prior {
            md.push_str(&format!(
                "\nSPAM starts each motion from its retrieval prior (the training split's \
                 motions, never this split's): it keeps {:.0} % of the tokens of a training \
                 motion whose caption is within {} of the nearest one's cosine similarity, \
                 when that is at least {}.\n",
                prior.keep * 100.0,
                prior.margin,
                prior.min_similarity
            ));
        }
        md.push_str("\n## Control probes\n\n| probe | figure |\n|---|---|\n");
        let p = &self.probes;
        // One line for the rate, one per prompt.
        let sided = |md: &mut String, what: &str, rate: f64, rows: &[(String, usize, usize)]| {
            md.push_str(&format!("| left/right: {what} | {:.1} % |\n", rate * 100.0));
            for (prompt, good, total) in rows {
                md.push_str(&format!("| &nbsp;&nbsp;\"{prompt}\" | {good}/{total} |\n"));
            }
        };
        if let Some(rate) = p.left_right_rate {
            sided(&mut md, "asked wrist ends higher", rate, &p.left_right);
        }
        if let Some(cm) = p.edit_leg_change_cm {
            md.push_str(&format!(
                "| left-arm edit of a walk, seeds 0–{}: mean leg-joint change | {cm:.2} cm |\n",
                super::probes::LOCALITY_SEEDS - 1
            ));
        }
        if let Some(cm) = p.edit_left_wrist_gain_cm {
            md.push_str(&format!(
                "| left-arm edit of a walk, seeds 0–{}: extra left-wrist rise | {cm:.1} cm |\n",
                super::probes::LOCALITY_SEEDS - 1
            ));
        }
        if let Some(j) = p.join_speeds {
            md.push_str(&format!(
                "| blend join: root speed (real 99th percentile) | {:.2} m/s ({:.2}) |\n| blend join: fastest joint (real 99th percentile) | {:.2} m/s ({:.2}) |\n",
                j.root, j.p99_root, j.joint, j.p99_joint
            ));
        }
        if let Some(legs) = &p.left_right_legs {
            sided(
                &mut md,
                "asked ankle rises higher",
                legs.rate,
                &legs.prompts,
            );
        }
        for a in &p.actions {
            md.push_str(&format!(
                "| \"{}\" ({} s, {} seeds): {} median (training motions' 10th percentile, median, 90th percentile) | {:.2}{u} ({:.2}{u}, {:.2}{u}, {:.2}{u}); {:.0} % of seeds reach the 10th percentile |\n",
                a.prompt,
                a.seconds,
                a.seeds,
                a.measure,
                a.median,
                a.real.p10,
                a.real.median,
                a.real.p90,
                a.reaching * 100.0,
                u = a.unit,
            ));
        }
        for name in ROW_ORDER {
            if let Some(row) = self.rows.get(name) {
                md.push_str(&format!(
                    "| foot skating ratio: {name} | {} |\n",
                    row.foot_skating
                ));
            }
        }
        for name in ROW_ORDER {
            if let Some(row) = self.rows.get(name) {
                md.push_str(&format!(
                    "| floating frames (no joint within 5 cm of the floor, longer than a 0.8 s jump): {name} | {} |\n",
                    row.floating
                ));
            }
        }
        for name in ROW_ORDER {
            if let Some(row) = self.rows.get(name) {
                md.push_str(&format!(
                    "| deepest joint under the floor, any frame: {name} | {:.3} m |\n",
                    row.floor_penetration
                ));
            }
        }
        md.push_str(&self.agents_markdown);
        md
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::metrics::Interval;

    fn row(repeats: usize) -> Row {
        let i = Interval {
            mean: 0.5,
            ci95: 0.01,
        };
        Row {
            top1: i,
            top2: i,
            top3: i,
            fid: i,
            mm_dist: i,
            diversity: i,
            multimodality: None,
            foot_skating: i,
            floating: i,
            floor_penetration: 0.0,
            repeats,
            top3_by_source: BTreeMap::new(),
        }
    }

    fn report(rows: BTreeMap<String, Row>, probes: Probes) -> EvalReport {
        EvalReport {
            command: "coma eval".into(),
            evaluator_id: "e".into(),
            spam_id: Some("s".into()),
            split: "test".into(),
            prior: None,
            test_motions: 300,
            options: ProtocolOptions::default(),
            rows,
            probes,
            agents: None,
            agents_markdown: String::new(),
            seconds: 1.0,
        }
    }

    #[test]
    fn a_row_measured_on_fewer_repetitions_says_so() {
        let report = report(
            [("spam".into(), row(10)), ("spam_review".into(), row(3))].into(),
            Probes::default(),
        );
        let md = report.markdown();
        let line = |name: &str| {
            md.lines()
                .find(|l| l.starts_with(&format!("- **{name}**")))
                .unwrap_or_else(|| panic!("no {name} line in\n{md}"))
                .to_string()
        };
        assert!(line("spam_review").ends_with("(measured on the first 3 of the 10 repetitions)"));
        assert!(!line("spam").contains("measured on"));
        assert!(report.json().contains("\"repeats\": 3"));
    }

    #[test]
    fn action_probes_and_kicks_show_their_bar_and_share() {
        let probes = Probes {
            left_right_legs: Some(crate::eval::probes::LeftRightReport {
                prompts: vec![("a person kicks with the left foot".into(), 19, 20)],
                rate: 0.95,
            }),
            actions: vec![ActionFigure {
                probe: "squat".into(),
                prompt: "a person does a squat".into(),
                measure: "pelvis drop".into(),
                unit: " m".into(),
                real: crate::eval::references::ActionReference {
                    motions: 40,
                    median: 0.42,
                    p10: 0.3,
                    p90: 0.5,
                    seconds: 1.6,
                },
                median: 0.35,
                reaching: 0.7,
                seeds: 20,
                seconds: 4.0,
            }],
            ..Probes::default()
        };
        let report = report(BTreeMap::new(), probes);
        let md = report.markdown();
        assert!(md.contains("| left/right: asked ankle rises higher | 95.0 % |"));
        assert!(md.contains("| &nbsp;&nbsp;\"a person kicks with the left foot\" | 19/20 |"));
        assert!(
            md.contains("| \"a person does a squat\" (4 s, 20 seeds): pelvis drop median (training motions' 10th percentile, median, 90th percentile) | 0.35 m (0.30 m, 0.42 m, 0.50 m); 70 % of seeds reach the 10th percentile |"),
            "{md}"
        );
        assert!(report.json().contains("\"reaching\": 0.7"));
    }
}
