//! A take: one state of the page's motion (tokens, joints and features) with what made it
//! (prompt, seed, the edits so far, the segments), as undo keeps it and a share link carries it.

use crate::messages::Motion;
use coma::share::{Edit, SharedMotion};

/// A stretch of the motion with its own text, in frames at 20 fps.
#[derive(Clone, Debug, PartialEq)]
pub struct Segment {
    pub text: String,
    pub from: usize,
    pub to: usize,
}

#[derive(Clone, Debug, PartialEq)]
pub struct Take {
    pub motion: Motion,
    pub prompt: String,
    pub seed: u64,
    pub edits: Vec<Edit>,
    pub segments: Vec<Segment>,
}

impl Take {
    /// Frames of the motion.
    pub fn frames(&self) -> usize {
        self.motion.joints.len()
    }

    /// What a share link of this take carries.
    pub fn shared(&self, model_id: [u8; 8]) -> SharedMotion {
        SharedMotion {
            model_id,
            seed: self.seed,
            prompt: self.prompt.clone(),
            plan: plan_json(&self.segments),
            history: self.edits.clone(),
            tokens: self.motion.tokens.clone(),
        }
    }
}

/// The segments as the plan a link carries.
pub fn plan_json(segments: &[Segment]) -> String {
    let list: Vec<_> = segments
        .iter()
        .map(|s| serde_json::json!({"text": s.text, "from": s.from, "to": s.to}))
        .collect();
    serde_json::json!({ "segments": list }).to_string()
}

/// Segments back from a link's plan; a plan that does not read gives one segment over the
/// whole motion with the prompt as its text.
pub fn segments_from_plan(plan: &str, prompt: &str, frames: usize) -> Vec<Segment> {
    let parsed: Option<Vec<Segment>> = serde_json::from_str::<serde_json::Value>(plan)
        .ok()
        .and_then(|v| {
            v.get("segments")?
                .as_array()?
                .iter()
                .map(|s| {
                    let from = s.get("from")?.as_u64()? as usize;
                    let to = s.get("to")?.as_u64()? as usize;
                    let text: String = s.get("text")?.as_str()?.chars().take(500).collect();
                    (from < to && to <= frames).then_some(Segment { text, from, to })
                })
                .collect()
        });
    match parsed {
        Some(s) if !s.is_empty() => s,
        _ => vec![Segment {
            text: prompt.to_string(),
            from: 0,
            to: frames,
        }],
    }
}

/// A short stable hash of the joints (FNV-1a over the f32 bits): two pages showing the same
/// motion show the same hash.
pub fn joints_hash(joints: &[[[f32; 3]; 22]]) -> String {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for v in joints.iter().flatten().flatten() {
        for b in v.to_bits().to_le_bytes() {
            h ^= b as u64;
            h = h.wrapping_mul(0x0100_0000_01b3);
        }
    }
    format!("{h:016x}")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn plans_round_trip_and_bad_plans_fall_back_to_one_segment() {
        let segments = vec![
            Segment {
                text: "walk forward".into(),
                from: 0,
                to: 80,
            },
            Segment {
                text: "bow".into(),
                from: 80,
                to: 120,
            },
        ];
        let plan = plan_json(&segments);
        assert_eq!(segments_from_plan(&plan, "p", 120), segments);
        for bad in [
            "",
            "{",
            r#"{"segments":[{"text":"x","from":5,"to":2}]}"#,
            r#"{"segments":[]}"#,
        ] {
            let s = segments_from_plan(bad, "the prompt", 60);
            assert_eq!(s.len(), 1);
            assert_eq!(
                (s[0].text.as_str(), s[0].from, s[0].to),
                ("the prompt", 0, 60)
            );
        }
        // A segment beyond the motion is not believed either.
        assert_eq!(segments_from_plan(&plan, "p", 100).len(), 1);
    }

    #[test]
    fn the_joints_hash_sees_every_value() {
        let a = vec![[[0.0f32; 3]; 22]; 3];
        let mut b = a.clone();
        assert_eq!(joints_hash(&a), joints_hash(&b));
        b[2][21][1] = 1e-6;
        assert_ne!(joints_hash(&a), joints_hash(&b));
    }
}
