//! The built-in planner: deterministic rules over the prompt's words, no LLM.
//!
//! 1. The prompt is cut into clauses at sentence ends and temporal connectives ("then",
//!    "after that", "finally", "before", "after", a comma or "and" that starts a new verb);
//!    "while" joins two clauses into one, and so does a comma before "holding", "keeping" or
//!    "with" (what the body keeps doing rides on the clause). "Before Y, X" and "X after Y"
//!    are put in time order (the `clauses` module). Context that is no movement (where, when,
//!    why, what the person feels) is dropped with a note (the `context` module).
//! 2. Each clause gets its movements from [`lexicon`]: one whole-body or walking motion as the
//!    base, and arm gestures beside it as part edits ("walks forward waving the left hand").
//!    A clause with no verb inherits the previous clause's gesture ("then the left hand"); a
//!    clause that lowers "it" brings down the arms raised before (the `anaphora` module).
//! 3. Repetitions ("twice") repeat the clause; durations come from "for N seconds", the
//!    action's usual length and tempo words; paths ("in a circle clockwise") from the
//!    trajectory shape library; style words ("angry", "elderly") become the caption phrases
//!    the data uses.
//! 4. A clause with no known movement is mapped, when an embedder is given, onto the training
//!    action or the library posture that means the same movement ([`meaning`]: calibrated
//!    threshold, same side, never the opposite direction; the `substitutes` module), and an
//!    arm phrase onto the gesture or arm posture it means (the `limbs` module); otherwise it
//!    is named in a note.
//! 5. Whatever a clause names that no segment makes is named in a note with the reason
//!    (the `accounting` module): no clause disappears silently. A plan lasts up to
//!    [`MAX_PLAN_SECONDS`]; clauses past it are named in a note.
//! 6. A posture or part instruction that runs over several consecutive segments becomes one
//!    clip on the body-part tracks (the `tracks` module).
//!
//! The actions of dataset v2 (squat, jump, lie down, kicks, throw, …) are planned as the
//! model's own motion only when the model's vocabulary lists them ([`plan_for`]); otherwise,
//! and for poses held ("holds a deep squat"), the posture library makes what it can of them.

use super::lexicon::{self, Action, Direction, Repertoire};
use super::meaning::{self, Matcher};
use super::postures;
use crate::dataset::Vocabulary;
use crate::plan::{
    clamp_seconds, in_time_order, PartEdits, Plan, PlannerKind, Segment, MAX_PLAN_SECONDS,
    MAX_SEGMENTS, MAX_TEXT_CHARS,
};
use crate::posture::library::NamedPosture;
use crate::posture::track::PostureTrack;
use crate::skeleton::BodyPart;

mod accounting;
mod anaphora;
mod clauses;
mod context;
mod limb_poses;
mod limbs;
mod placing;
mod reading;
mod substitutes;
mod torso_poses;
mod tracks;

use clauses::{clauses, tokens};
use context::without_context;
use placing::*;
use reading::*;
use substitutes::{nearest_action, nearest_library_entry};

/// Turns a sentence into a unit embedding (MiniLM); the planner uses it to map movements it
/// has no rule for onto the nearest action of the training data.
pub type Embedder<'a> = &'a dyn Fn(&str) -> Vec<f32>;

/// How a note says a clause was planned as a different movement than it asks for.
pub const SUBSTITUTED: &str = "is not a movement the model knows";
/// How a note says a clause was left out of the plan.
pub const LEFT_OUT: &str = "names no movement the model makes; left out";
/// How a note says no rule read a clause at all (a gap in the rules, never expected: the
/// prompt sets' test fails on it).
pub const UNREAD: &str = "was read by no rule of the built-in planner; left out";
/// How a note says a clause was made as a movement the model knows that says it in other
/// words, not plainly the same ("sidesteps to the right" as "a person walks to the right").
pub const MADE_AS: &str = "is made as the nearest movement the model knows";
/// How a note says a part of a clause was left out of the plan (the reason follows).
pub const NOT_PLACED: &str = "was left out of the plan";

/// Whether a plan note says a clause went unplanned: planned as a different movement (the
/// nearest one the model knows) or left out.
pub fn is_unplanned_note(note: &str) -> bool {
    [SUBSTITUTED, LEFT_OUT, NOT_PLACED, UNREAD]
        .iter()
        .any(|said| note.contains(said))
}

/// Longest prompt read, in characters; the rest is ignored with a note.
pub const MAX_PROMPT_CHARS: usize = 2000;

/// Plans `prompt` with the built-in rules for a model that knows the Bandai Namco actions
/// only (as [`plan_for`] with no vocabulary).
pub fn plan(prompt: &str, embed: Option<Embedder>) -> Plan {
    plan_for(prompt, None, embed)
}

/// Plans `prompt` with the built-in rules for the model whose training vocabulary is
/// `vocabulary`: the actions of dataset v2 it lists are made by the model. `embed` (optional)
/// maps unknown movements onto the training actions. Always returns a plan of 1 to
/// [`MAX_SEGMENTS`] segments, [`MAX_PLAN_SECONDS`] at most.
pub fn plan_for(prompt: &str, vocabulary: Option<&Vocabulary>, embed: Option<Embedder>) -> Plan {
    let known = Repertoire::new(vocabulary);
    // One judgement of "the same movement" for the whole prompt, each text embedded once.
    let similarity = embed.map(meaning::embedding_similarity);
    let matcher = similarity
        .as_ref()
        .map(|s| Matcher::new(s, meaning::SAME_MOVEMENT_MIN_SIMILARITY));
    let mut notes = Vec::new();
    let mut text: String = prompt.chars().take(MAX_PROMPT_CHARS).collect();
    if prompt.chars().count() > MAX_PROMPT_CHARS {
        notes.push(format!(
            "the prompt is longer than {MAX_PROMPT_CHARS} characters; the rest was not read"
        ));
    }
    text = text.to_lowercase();
    let style = prompt_style(&text);
    let mut segments: Vec<Segment> = Vec::new();
    let mut previous: Option<Action> = None;
    // The dataset v2 action the last segment made, whose clip ends standing again.
    let mut ends_standing: Option<Action> = None;
    let clauses = clauses(&text, known);
    let clauses = without_context(&clauses, known, &mut notes);
    let readers: Vec<Reader> = (0..clauses.len())
        .map(|k| Reader {
            known,
            pose_kept: clauses
                .get(k + 1)
                .is_some_and(|next| postures::keeps_pose_before(next)),
        })
        .collect();
    // The clause each segment came from.
    let mut clause_of: Vec<usize> = Vec::new();
    // Limb poses read from the words, held over a clause's segments (their indices).
    let mut held: Vec<(std::ops::Range<usize>, NamedPosture)> = Vec::new();
    // The places (indices into `held`) a clause of their own put limbs in, which stay over
    // the next clause if it leaves those limbs alone.
    let mut lasting: Vec<usize> = Vec::new();
    for (k, words) in clauses.iter().enumerate() {
        let words = with_subject_whole(words, readers[k]);
        let words = words.as_slice();
        let reader = readers[k];
        let clause_start = segments.len();
        let notes_start = notes.len();
        let mut lasting_now: Vec<usize> = Vec::new();
        'clause: {
            let only_stands_up =
                || postures::stands_up(words) && movements(words, None, reader).is_none();
            if let Some(action) = ends_standing.filter(|_| only_stands_up()) {
                // "squats down and stands back up": the squat's clips stand back up already.
                notes.push(format!(
                    "\"{}\" is made by the movement before: \"{}\" ends standing",
                    words.join(" "),
                    action.verb_phrase()
                ));
                break 'clause;
            }
            if let Some(across) = segments
                .last()
                .filter(|_| anaphora::goes_back(words))
                .and_then(anaphora::back_across)
            {
                // "steps to the left, then back to the centre": the way back is to the right.
                notes.push(format!(
                    "\"{}\": back the way the movement before went, to the other side",
                    words.join(" ")
                ));
                segments.push(across);
                previous = None;
                ends_standing = None;
                break 'clause;
            }
            let model = movements(words, previous, reader);
            let next_dataset_action = clauses
                .get(k + 1)
                .and_then(|next| movements(next, None, readers[k + 1]))
                .map(|m| m.base)
                .filter(|a| a.label().is_some());
            if let Some(next) = next_dataset_action
                .filter(|next| model.is_none() && postures::leads_into(words, *next))
            {
                // "kneels and then lies down": the model's lying down kneels on the way.
                notes.push(format!(
                    "\"{}\" is made by the movement after: \"{}\" passes through it",
                    words.join(" "),
                    next.verb_phrase()
                ));
                break 'clause;
            }
            let model_segment = || match &model {
                Some(found) => segment(words, found, style.as_deref()),
                None => segment(
                    words,
                    &Movements::only(Action::Walk(Direction::Forward)),
                    style.as_deref(),
                ),
            };
            // "steps forward with the left foot", "leans to the left": key poses of the
            // whole body the rules write themselves.
            let own_track = super::sided::single_step(words).or_else(|| {
                model
                    .is_none()
                    .then(|| torso_poses::torso_pose(words))
                    .flatten()
                    .map(|pose| PostureTrack::holding(pose.parts, pose.script))
            });
            if let Some(track) = own_track {
                let text = format!("a person {}", lexicon::without_subject(words).join(" "));
                segments.push(standing_segment(text, Some(track)));
                previous = None;
                ends_standing = None;
                // "sidesteps to the right with both arms crossed": what rides on the step.
                // The foot a step names is the step's own ("steps to the left with the left
                // foot").
                let named: Vec<usize> = super::sided::leg_words(words).collect();
                let made = &mut segments[clause_start..];
                let poses = place_limb_phrases(words, &named, matcher.as_ref(), made, &mut notes);
                let span = clause_start..segments.len();
                held.extend(poses.into_iter().map(|p| (span.clone(), p)));
                break 'clause;
            }
            if let Some(held) = segments
                .last()
                .filter(|last| postures::holds_by_name(words, last))
                .and_then(|last| postures::hold_segment(words, last))
            {
                segments.push(held);
                break 'clause;
            }
            let model_parts = model.as_ref().map(|m| (m.base, m.gestures.as_slice()));
            if let Some(planned) = postures::plan_clause(words, model_parts, &model_segment) {
                notes.extend(planned.notes);
                postures::land_in(words, segments.last_mut(), &planned.segment);
                previous = None;
                ends_standing = None;
                // A dataset action with a posture held on its arms is still the model's movement,
                // counted as one ("does two squats in a T-pose").
                let times = match &model {
                    Some(found) if planned.over_model && found.base.label().is_some() => {
                        ends_standing = Some(found.base).filter(|a| *a != Action::LieDown);
                        repetitions(words, found, &mut notes)
                    }
                    _ => 1,
                };
                for _ in 0..times {
                    segments.push(planned.segment.clone());
                }
                if let Some(found) = model.as_ref().filter(|_| planned.over_model) {
                    // "from a walk to a run, holding the T-pose": the run holds it too.
                    let held = model_segment();
                    for (_, mut next) in moves_on(words, found, style.as_deref(), &mut notes) {
                        next.text = planned.segment.text.replacen(&held.text, &next.text, 1);
                        next.postures = planned.segment.postures.clone();
                        next.parts = planned.segment.parts.clone();
                        segments.push(next);
                    }
                }
                // A clause that moves on ("from a walk to a run") is said by all its segments,
                // not by the first.
                let moved_on = model
                    .as_ref()
                    .is_some_and(|m| moves_on_in_sequence(words, m));
                if planned.over_model && !moved_on {
                    notes.extend(said_otherwise(words, &model_segment(), matcher.as_ref()));
                }
                let made = &mut segments[clause_start..];
                let poses =
                    place_limb_phrases(words, &planned.named, matcher.as_ref(), made, &mut notes);
                let span = clause_start..segments.len();
                held.extend(poses.into_iter().map(|p| (span.clone(), p)));
                break 'clause;
            }
            if let Some((stance, poses)) = model.is_none().then(|| standing_poses(words)).flatten()
            {
                // "stands on the left leg while stretching the right leg out behind her". After
                // a pose of the whole body ("drops to one knee, spreads both arms wide") the
                // body stays in that pose.
                let kept = segments
                    .last()
                    .filter(|_| stance.postures.is_none())
                    .filter(|last| last.postures.as_ref().is_some_and(|t| t.whole_body()))
                    .and_then(|last| postures::hold_segment(words, last))
                    .map(|mut kept| {
                        for key in kept.postures.iter_mut().flat_map(|t| t.keys.iter_mut()) {
                            key.script.name = key.script.name.as_deref().map(anaphora::held_name);
                        }
                        kept
                    });
                segments.push(kept.unwrap_or(stance));
                let span = clause_start..segments.len();
                lasting_now.extend(held.len()..held.len() + poses.len());
                held.extend(poses.into_iter().map(|p| (span.clone(), p)));
                previous = None;
                ends_standing = None;
                break 'clause;
            }
            // "lifts the right knee, holds it": the places the clause before reached, kept
            // over a clip of their own; "raises both hands, holds them up": the arms up.
            if let Some(poses) = model
                .is_none()
                .then(|| anaphora::holds_back(words))
                .filter(|holds| *holds)
                .and_then(|_| kept_places(&held, clause_start, segments.last()))
            {
                let names: Vec<&str> = poses.iter().map(|p| p.name.as_str()).collect();
                let text = format!("a person holds still, {}", names.join(", "));
                let body = segments
                    .last()
                    .filter(|last| last.postures.as_ref().is_some_and(|t| t.whole_body()))
                    .and_then(|last| postures::hold_segment(words, last))
                    .unwrap_or_else(|| standing_segment(text, None));
                segments.push(body);
                let span = clause_start..segments.len();
                held.extend(poses.into_iter().map(|mut p| {
                    p.name = anaphora::held_name(&p.name);
                    p.script.name = Some(p.name.clone());
                    (span.clone(), p)
                }));
                previous = None;
                break 'clause;
            }
            if let (None, Some(stay)) = (&model, postures::stay(words)) {
                let held = match (stay, segments.last()) {
                    (postures::Stay::Hold, Some(last)) => postures::hold_segment(words, last),
                    _ => None,
                };
                let said = words.join(" ");
                match (held, segments.last_mut()) {
                    (Some(held), _) => segments.push(held),
                    (None, Some(last)) if stay != postures::Stay::Passing => {
                        // Staying as one is: the movement before lasts longer.
                        last.seconds = clamp_seconds(last.seconds + postures::HOLD_EXTRA_SECONDS)
                            .unwrap_or(last.seconds);
                        notes.push(format!("\"{said}\": the movement before lasts longer"));
                    }
                    (None, _) if stay == postures::Stay::Passing => notes.push(format!(
                        "\"{said}\" happens on the way from one movement to the next; no \
                         movement of its own"
                    )),
                    (None, _) => notes.push(format!(
                        "\"{said}\" {NOT_PLACED}: there is no movement before it to last longer"
                    )),
                }
                break 'clause;
            }
            // "stretches her left arm to the side, and then the right one": the places held
            // over the clause before, on the side asked, over its movement once more.
            let held_before = held
                .last()
                .map(|(span, _)| span.clone())
                .filter(|span| span.end == clause_start && !span.is_empty());
            if let Some((span, poses)) = model
                .is_none()
                .then(|| anaphora::again(words))
                .flatten()
                .zip(held_before)
                .and_then(|(a, span)| {
                    let poses: Vec<NamedPosture> = held
                        .iter()
                        .filter(|(s, _)| *s == span)
                        .map(|(_, p)| p.clone())
                        .collect();
                    Some((span, anaphora::repeated_poses(&poses, a)?))
                })
            {
                segments.extend(segments[span].to_vec());
                let again = clause_start..segments.len();
                held.extend(poses.into_iter().map(|p| (again.clone(), p)));
                break 'clause;
            }
            if let Some(once_more) = model
                .is_none()
                .then(|| anaphora::again(words))
                .flatten()
                .and_then(|a| {
                    let last = segments.iter().rposition(|s| !anaphora::is_lowering(s))?;
                    let one = anaphora::repeated(&segments[last], a)?;
                    // "sits down, then gets up and does the same thing again": getting up
                    // ends what is done again, so the movement before it comes back too.
                    Some(match last.checked_sub(1) {
                        Some(before) if a == anaphora::Again::Same && gets_up(&segments[last]) => {
                            vec![segments[before].clone(), one]
                        }
                        _ => vec![one],
                    })
                })
            {
                // "waves with the left hand, then with the right"; "repeats it twice more".
                for _ in 0..lexicon::repetitions(words) {
                    segments.extend(once_more.iter().cloned());
                }
                break 'clause;
            }
            // After a raise, "puts it back down" lowers the arm; after anything else (picking
            // a box up) it is the model's putting down.
            let after_raise = segments.last().is_some_and(|s| {
                let said_raise = s
                    .text
                    .split(' ')
                    .any(|w| matches!(w, "raise" | "raises" | "lift" | "lifts"));
                said_raise && !anaphora::raised_arms(s).is_empty()
            });
            // "lifts the right knee, holds it, and then puts it down": the limbs held just
            // before.
            let held_before: Vec<BodyPart> = held_just_before(&held, clause_start)
                .flat_map(|p| p.parts.clone())
                .collect();
            if let Some(lowered) = (model.is_none() || after_raise || !held_before.is_empty())
                .then(|| lowered_back(words, segments.last(), &held_before))
                .flatten()
            {
                segments.push(lowered);
                previous = None;
                break 'clause;
            }
            let action = model
                .is_none()
                .then(|| nearest_action(words, matcher.as_ref(), known));
            if let Some((name, similarity)) = model
                .is_none()
                .then(|| nearest_library_entry(words, matcher.as_ref()))
                .flatten()
                .filter(|(_, s)| action.flatten().is_none_or(|(_, a)| *s > a))
            {
                // "sits" is the library's "sit on a chair": planned as if the clause named it.
                let named: Vec<&str> = name.split(' ').collect();
                if let Some(planned) = postures::plan_clause(&named, None, &model_segment) {
                    notes.push(format!(
                        "\"{}\" {SUBSTITUTED}; used the posture library's \"{name}\" \
                         (similarity {similarity:.2})",
                        words.join(" ")
                    ));
                    notes.extend(planned.notes);
                    segments.push(planned.segment);
                    previous = None;
                    ends_standing = None;
                    break 'clause;
                }
            }
            let from_rules = model.is_some();
            let found = match model {
                Some(found) => found,
                None => match action.flatten() {
                    Some((action, similarity)) => {
                        notes.push(format!(
                            "\"{}\" {SUBSTITUTED}; used the nearest one, \"{}\" \
                             (similarity {similarity:.2})",
                            words.join(" "),
                            action.verb_phrase()
                        ));
                        Movements::only(action)
                    }
                    None => {
                        if !words.is_empty() {
                            notes.push(format!("\"{}\" {LEFT_OUT}", words.join(" ")));
                        }
                        break 'clause;
                    }
                },
            };
            let made = segment(words, &found, style.as_deref());
            if from_rules && !moves_on_in_sequence(words, &found) {
                notes.extend(said_otherwise(words, &made, matcher.as_ref()));
            }
            for _ in 0..repetitions(words, &found, &mut notes) {
                segments.push(made.clone());
            }
            let mut last = found.base;
            for (action, next) in moves_on(words, &found, style.as_deref(), &mut notes) {
                segments.push(next);
                last = action;
            }
            // A substitute or an inherited gesture stands for the whole clause.
            if !found.named.is_empty() {
                let made = &mut segments[clause_start..];
                let poses =
                    place_limb_phrases(words, &found.named, matcher.as_ref(), made, &mut notes);
                let span = clause_start..segments.len();
                held.extend(poses.into_iter().map(|p| (span.clone(), p)));
            }
            previous = Some(found.gestures.last().copied().unwrap_or(last));
            ends_standing = Some(last).filter(|a| a.label().is_some() && *a != Action::LieDown);
        }
        // What the clause says of a limb that nothing moves or holds is named too.
        let held_parts: Vec<BodyPart> = held
            .iter()
            .filter(|(span, _)| span.start == clause_start)
            .flat_map(|(_, p)| p.parts.clone())
            .collect();
        for (phrase, limb) in
            accounting::limbs_left_unplaced(words, &segments[clause_start..], &held_parts, &notes)
        {
            notes.push(format!(
                "\"{phrase}\" {NOT_PLACED}: the built-in planner has no rule for this movement \
                 of the {limb}"
            ));
        }
        // A phrase of a clause that made something, which left no trace in it, is named too
        // ("hops forward on the right foot, arms flapping like wings").
        if segments.len() > clause_start {
            let made = accounting::made_words(
                &segments[clause_start..],
                held.iter()
                    .filter(|(span, _)| span.start == clause_start)
                    .map(|(_, p)| p.name.clone()),
                &notes[notes_start..],
            );
            for phrase in accounting::phrases_without_trace(words, &made) {
                notes.push(format!(
                    "\"{phrase}\" {NOT_PLACED}: the built-in planner made nothing of it"
                ));
            }
        }
        // A safety net under the rules: a clause that neither made a segment nor left a note
        // is named now. The prompt sets' test checks the rules never need it.
        if segments.len() == clause_start && notes.len() == notes_start && !words.is_empty() {
            notes.push(format!("\"{}\" {UNREAD}", words.join(" ")));
        }
        // "puts her left hand on her hip and waves with the right": a limb a clause of its
        // own placed stays there over the next clause, unless that clause moves it or only
        // does the same on another limb ("…, and then the right one": one after the other).
        let repeats = anaphora::again(words).is_some();
        for i in std::mem::replace(&mut lasting, lasting_now)
            .into_iter()
            .filter(|_| !repeats)
        {
            let parts = held[i].1.parts.clone();
            let moved_now = held.iter().any(|(span, p)| {
                span.start == clause_start && p.parts.iter().any(|x| parts.contains(x))
            });
            let free = segments[clause_start..].iter().all(|s| {
                busy(s, &parts).is_none() && !s.postures.as_ref().is_some_and(|t| t.whole_body())
            });
            if held[i].0.end == clause_start && segments.len() > clause_start && free && !moved_now
            {
                held[i].0.end = segments.len();
            }
        }
        clause_of.resize(segments.len(), k);
    }
    if segments.is_empty() {
        let fallback =
            crate::plan::clean_text(prompt).unwrap_or_else(|_| "a person walks forward".into());
        let fallback: String = fallback.chars().take(MAX_TEXT_CHARS).collect();
        notes.push("no known movement in the prompt; the model gets the prompt as it is".into());
        segments.push(Segment {
            text: fallback.clone(),
            seconds: 4.0,
            base: fallback,
            parts: PartEdits::default(),
            trajectory: None,
            postures: None,
        });
    }
    // The segments that fit in the longest plan; the rest are named in a note.
    let mut total = 0.0;
    let fit = segments
        .iter()
        .take_while(|s| {
            total += s.seconds;
            total <= MAX_PLAN_SECONDS + 1e-6
        })
        .count()
        .clamp(1, MAX_SEGMENTS);
    if fit < segments.len() {
        let dropped: Vec<String> = segments[fit..].iter().map(|s| s.text.clone()).collect();
        notes.push(format!(
            "a plan lasts at most {MAX_PLAN_SECONDS} s; left out: {}",
            dropped.join("; ")
        ));
        segments.truncate(fit);
    }
    let mut clips = tracks::clips_across_segments(&mut segments, &clause_of);
    clips.extend(tracks::held_clips(&segments, &held));
    in_time_order(&mut clips);
    Plan {
        prompt: prompt.to_string(),
        rewritten: rewrite(&segments),
        segments,
        clips,
        planner: PlannerKind::Offline,
        notes,
    }
}

/// The segments' texts as one description ("a person walks forward, then a person bows").
pub fn rewrite(segments: &[Segment]) -> String {
    segments
        .iter()
        .map(|s| s.text.as_str())
        .collect::<Vec<_>>()
        .join(", then ")
}

#[cfg(test)]
mod tests;
