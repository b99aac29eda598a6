//! Posture tracks: the key poses a plan's segment asks for, and how they are laid over the
//! motion the model generated ([`lay_tracks`]).
//!
//! A track on all four body parts is a *posture segment*: its key poses replace the generated
//! motion over the segment's frames, root included, starting from the pose the motion is in
//! and ending in the pose the next segment starts with, so segments join without a jump. A
//! track on some parts is *held* on those parts over the generated motion (a T-pose on the arms
//! of a walk), eased in and out.

use super::go::{self, KeyPose, Transition};
use super::script::PostureScript;
use super::solver::{solve, Angles};
use crate::geom::{self, Quat, Vec3};
use crate::posecodes::{body_level, facing, torso_lean, Lean, PelvisLevel};
use crate::skeleton::{self, BodyPart, Offsets, Pose};
use crate::timing::FPS;
use serde::{Deserialize, Serialize};
use std::ops::Range;

/// Most key poses in one track.
pub const MAX_KEYS: usize = 8;
/// Most repetitions of a track's keys (squats × 10).
pub const MAX_REPEAT: u32 = 10;
/// Longest transition into a key, seconds.
pub const MAX_TRANSITION_SECONDS: f64 = 5.0;
/// Transition into a key when the track does not say, seconds.
pub const DEFAULT_TRANSITION_SECONDS: f64 = 0.8;
/// Largest turn at one key, degrees (two full spins).
pub const MAX_TURN_DEG: f64 = 720.0;
/// Largest travel at one key, metres along each ground axis.
pub const MAX_TRAVEL_M: f64 = 3.0;
/// Highest jump, metres the pelvis rises at the top of the flight.
pub const MAX_JUMP_M: f64 = 1.0;
/// Time (seconds) a held posture takes to let go of its parts at the end of its range.
pub const RELEASE_SECONDS: f64 = 0.5;

/// One key pose of a track and how it is reached.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TrackKey {
    /// The pose (its `hold` is how long it is held, seconds).
    pub script: PostureScript,
    /// Seconds to move into the pose from the previous one (0 to [`MAX_TRANSITION_SECONDS`]).
    #[serde(default = "default_transition")]
    pub transition: f64,
    /// Turn on the spot reached at this key, degrees, + to the left (counter-clockwise seen
    /// from above); 360 is a full spin.
    #[serde(default, skip_serializing_if = "is_zero")]
    pub turn_deg: f64,
    /// Ground travel `[left, forward]` in metres, in the facing of the previous key, covered
    /// while moving into this key (crawling forward, a step).
    #[serde(default, skip_serializing_if = "is_zero2")]
    pub travel: [f64; 2],
    /// A jump into this key: the height in metres the pelvis rises at the top of the flight.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub jump_m: Option<f64>,
}

fn default_transition() -> f64 {
    DEFAULT_TRANSITION_SECONDS
}

fn is_zero(v: &f64) -> bool {
    *v == 0.0
}

fn is_zero2(v: &[f64; 2]) -> bool {
    v[0] == 0.0 && v[1] == 0.0
}

fn is_zero_u32(v: &u32) -> bool {
    *v == 0
}

fn one() -> u32 {
    1
}

/// The key poses of one plan segment.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "TrackFields")]
pub struct PostureTrack {
    /// The body parts that follow the key poses. All four make a posture segment (the key poses
    /// replace the generated motion, root included); fewer hold the poses on those parts over
    /// the generated motion.
    pub parts: Vec<BodyPart>,
    /// The key poses in order (1 to [`MAX_KEYS`]).
    pub keys: Vec<TrackKey>,
    /// How many times the keys are played (1 to [`MAX_REPEAT`]); a repeated track comes back to
    /// the pose it started from between and after the repetitions (squats × 3), or, with a
    /// lead-in, to the lead-in's last key (see [`PostureTrack::played`]).
    #[serde(default = "one")]
    pub repeat: u32,
    /// How many of the first keys lead into the cycle and are played once (push-ups: get into
    /// the plank once, then down and up again); 0 when the whole track is the cycle. Fewer than
    /// the keys.
    #[serde(default, skip_serializing_if = "is_zero_u32")]
    pub lead_in: u32,
    /// Whether the track ends back in the pose it started from (a squat goes down and comes
    /// up; "sits down" stays down).
    #[serde(default)]
    pub returns: bool,
    /// The time range the track covers, seconds from the start of its segment `[from, to]`;
    /// the whole segment when absent (a posture chosen in the page for part of a segment).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub within: Option<[f64; 2]>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct TrackFields {
    parts: Vec<BodyPart>,
    keys: Vec<TrackKey>,
    #[serde(default = "one")]
    repeat: u32,
    #[serde(default)]
    lead_in: u32,
    #[serde(default)]
    returns: bool,
    #[serde(default)]
    within: Option<[f64; 2]>,
}

impl TryFrom<TrackFields> for PostureTrack {
    type Error = String;

    fn try_from(f: TrackFields) -> Result<PostureTrack, String> {
        PostureTrack {
            parts: f.parts,
            keys: f.keys,
            repeat: f.repeat,
            lead_in: f.lead_in,
            returns: f.returns,
            within: f.within,
        }
        .checked()
    }
}

impl PostureTrack {
    /// A track of one key pose held on `parts`.
    pub fn holding(parts: Vec<BodyPart>, script: PostureScript) -> PostureTrack {
        PostureTrack {
            parts,
            keys: vec![TrackKey {
                script,
                transition: DEFAULT_TRANSITION_SECONDS,
                turn_deg: 0.0,
                travel: [0.0, 0.0],
                jump_m: None,
            }],
            repeat: 1,
            lead_in: 0,
            returns: false,
            within: None,
        }
    }

    /// Checks the bounds (parts, number of keys, repetitions, times, turns, travel, jumps) and
    /// each key's script; messages name the key.
    pub fn checked(mut self) -> Result<PostureTrack, String> {
        if self.parts.is_empty() {
            return Err("a posture track needs at least one body part".into());
        }
        self.parts.sort();
        self.parts.dedup();
        if self.keys.is_empty() || self.keys.len() > MAX_KEYS {
            return Err(format!(
                "a posture track has 1 to {MAX_KEYS} key poses, this one {}",
                self.keys.len()
            ));
        }
        if let Some([from, to]) = self.within {
            if !(from.is_finite() && to.is_finite() && 0.0 <= from && from < to) {
                return Err(format!(
                    "a posture track's time range must be two times in seconds, the first \
                     before the second, not [{from}, {to}]"
                ));
            }
        }
        if self.lead_in as usize >= self.keys.len() {
            return Err(format!(
                "a posture track's lead-in must be fewer key poses than the track has ({}), not {}",
                self.keys.len(),
                self.lead_in
            ));
        }
        if !(1..=MAX_REPEAT).contains(&self.repeat) {
            return Err(format!(
                "a posture track repeats 1 to {MAX_REPEAT} times, not {}",
                self.repeat
            ));
        }
        for (i, k) in self.keys.iter_mut().enumerate() {
            let bounded = |v: f64, lo: f64, hi: f64, what: &str| {
                if v.is_finite() && (lo..=hi).contains(&v) {
                    Ok(v)
                } else {
                    Err(format!(
                        "key pose {}: {what} must be from {lo} to {hi}, not {v}",
                        i + 1
                    ))
                }
            };
            k.transition = bounded(k.transition, 0.0, MAX_TRANSITION_SECONDS, "transition (s)")?;
            k.turn_deg = bounded(k.turn_deg, -MAX_TURN_DEG, MAX_TURN_DEG, "turn (degrees)")?;
            for t in &mut k.travel {
                *t = bounded(*t, -MAX_TRAVEL_M, MAX_TRAVEL_M, "travel (m)")?;
            }
            if let Some(j) = k.jump_m {
                k.jump_m = Some(bounded(j, 0.0, MAX_JUMP_M, "jump height (m)")?);
            }
            k.script = k
                .script
                .clone()
                .check()
                .map_err(|e| format!("key pose {}: {e}", i + 1))?;
        }
        Ok(self)
    }

    /// The frames (20 fps) the track covers within a segment that covers `segment`.
    pub fn frames_within(&self, segment: Range<usize>) -> Range<usize> {
        match self.within {
            Some([from, to]) => {
                let at = |s: f64| (segment.start + (s * FPS).round() as usize).min(segment.end);
                at(from)..at(to).max(at(from))
            }
            None => segment,
        }
    }

    /// Whether the track drives the whole body, root included.
    pub fn whole_body(&self) -> bool {
        self.parts.len() == BodyPart::ALL.len()
    }

    /// The order the go stage plays the keys in after the pose the track starts from:
    /// `Some(i)` is key `i`, `None` the way back to the starting pose. The lead-in keys come
    /// once, then the cycle `repeat` times; between repetitions the body comes back to where
    /// the cycle starts (the lead-in's last key, or the starting pose), and a track that
    /// returns or repeats ends in the starting pose.
    pub fn played(&self) -> Vec<Option<usize>> {
        let lead = (self.lead_in as usize).min(self.keys.len().saturating_sub(1));
        let cycle: Vec<Option<usize>> = (lead..self.keys.len()).map(Some).collect();
        let back = lead.checked_sub(1);
        let mut out: Vec<Option<usize>> = (0..lead).map(Some).collect();
        for n in 0..self.repeat.max(1) {
            if n > 0 {
                out.push(back);
            }
            out.extend(&cycle);
        }
        let repeated = self.repeat > 1;
        if lead > 0 && repeated {
            out.push(back);
        }
        if self.returns || (lead == 0 && repeated) {
            out.push(None);
        }
        out
    }

    /// Seconds to move into a played key (`None`: back to the start, at the first key's pace)
    /// and to hold it.
    fn timing(&self, key: Option<usize>) -> (f64, f64) {
        match key {
            Some(i) => (self.keys[i].transition, self.keys[i].script.hold),
            None => (self.keys[0].transition, 0.0),
        }
    }

    /// Seconds the track takes at its own pace: every transition and hold as played.
    pub fn natural_seconds(&self) -> f64 {
        self.played()
            .into_iter()
            .map(|k| {
                let (moving, hold) = self.timing(k);
                moving + hold
            })
            .sum()
    }

    /// The factors `(holds, transitions)` that make the track last `seconds`: spare time
    /// lengthens the holds (or, with none, the transitions), missing time shortens everything.
    pub fn time_scales(&self, seconds: f64) -> (f64, f64) {
        let natural = self.natural_seconds().max(1e-6);
        let holds: f64 = self.played().into_iter().map(|k| self.timing(k).1).sum();
        if seconds >= natural && holds > 0.0 {
            (1.0 + (seconds - natural) / holds, 1.0)
        } else {
            (seconds / natural, seconds / natural)
        }
    }

    /// When each key pose is reached when the track lasts `seconds`, by its own timing scaled
    /// as [`PostureTrack::time_scales`] says, in the order [`PostureTrack::played`] gives:
    /// `(reached s, held s, key index)`; the ways back to the start are not listed. The go stage
    /// may still lengthen a transition that would move a joint too fast; these times do not
    /// follow that.
    pub fn key_times(&self, seconds: f64) -> Vec<(f64, f64, usize)> {
        let (hold_scale, move_scale) = self.time_scales(seconds);
        let mut out = Vec::new();
        let mut t = 0.0;
        for k in self.played() {
            let (moving, hold) = self.timing(k);
            t += moving * move_scale;
            if let Some(i) = k {
                out.push((t, hold * hold_scale, i));
            }
            t += hold * hold_scale;
        }
        out
    }

    /// The track in words for the plan view ("key 1 (squat, held 0.6 s): the left knee is …").
    pub fn in_words(&self) -> Vec<String> {
        self.keys
            .iter()
            .enumerate()
            .map(|(i, k)| {
                format!(
                    "key {} ({}, held {:.1} s): {}",
                    i + 1,
                    k.script.name.as_deref().unwrap_or("posture"),
                    k.script.hold,
                    k.script.in_words()
                )
            })
            .collect()
    }
}

/// Poses the body passes through between standing and lying, so that it gets down to the floor
/// and up again as people do (sitting down before lying back, kneeling on hands and knees
/// before lying face down) instead of tipping over as one piece. Key shapes at the origin
/// facing +Z, lowest joint on the floor; the named library provides them
/// (`Library::bridges`).
#[derive(Clone, Copy, Debug)]
pub struct Bridges {
    /// Passed through to and from lying on the back or side: sitting on the floor.
    pub back: Pose,
    /// Passed through to and from lying face down: on hands and knees.
    pub front: Pose,
}

impl Bridges {
    /// The pose to pass through from key shape `a` to key shape `b`, if one is on the floor
    /// lying and the other upright (standing or crouching).
    fn between(&self, a: &Pose, b: &Pose) -> Option<Pose> {
        let level = |p: &Pose| body_level(p, 0.0);
        let upright = |p: &Pose| matches!(level(p), PelvisLevel::Standing | PelvisLevel::Crouching);
        // A plank also reads as lying, but people get into it from a crouch, hands first.
        let lying = |p: &Pose| {
            level(p) == PelvisLevel::Lying && p[crate::skeleton::joint::PELVIS][1] < FLAT_PELVIS_M
        };
        let down = if upright(a) && lying(b) {
            b
        } else if lying(a) && upright(b) {
            a
        } else {
            return None;
        };
        Some(match torso_lean(down) {
            Lean::Forward => self.front,
            _ => self.back,
        })
    }
}

/// Pelvis height (metres) under which a lying key is flat on the floor and is reached through
/// a bridge pose; a push-up plank holds the pelvis higher.
const FLAT_PELVIS_M: f64 = 0.2;
/// Share of an eased transition each half takes when a bridge pose splits it: more than half,
/// since the body now travels further.
const BRIDGE_SHARE: f64 = 0.6;
/// Seconds a bridge pose is held.
const BRIDGE_HOLD: f64 = 0.1;

/// Inserts a bridge pose into every eased transition between upright and lying keys (see
/// [`Bridges`]); `labels` (the track key each go key shows, if any) gets `None` for each.
fn bridged(
    keys: Vec<KeyPose>,
    labels: Vec<Option<usize>>,
    bridges: Option<&Bridges>,
) -> (Vec<KeyPose>, Vec<Option<usize>>) {
    let Some(bridges) = bridges else {
        return (keys, labels);
    };
    let mut out = Vec::with_capacity(keys.len());
    let mut out_labels = Vec::with_capacity(labels.len());
    for (i, (key, label)) in keys.into_iter().zip(labels).enumerate() {
        let eased = key.motion == Transition::Ease;
        let through = (i > 0 && eased)
            .then(|| {
                bridges.between(
                    &out.last().map_or(key.pose, |k: &KeyPose| k.pose),
                    &key.pose,
                )
            })
            .flatten();
        match through {
            Some(pose) => {
                out.push(KeyPose::new(
                    pose,
                    key.transition * BRIDGE_SHARE,
                    BRIDGE_HOLD,
                ));
                out_labels.push(None);
                out.push(KeyPose {
                    transition: key.transition * BRIDGE_SHARE,
                    ..key
                });
            }
            None => out.push(key),
        }
        out_labels.push(label);
    }
    (out, out_labels)
}

/// A track placed on frames of the motion (20 fps).
#[derive(Clone, Debug)]
pub struct TrackSpan<'a> {
    /// The frames the track covers.
    pub frames: Range<usize>,
    /// The track.
    pub track: &'a PostureTrack,
}

/// Where a pose stands: pelvis on the ground plane and heading (radians, 0 = facing +Z,
/// + = turned left).
#[derive(Clone, Copy, Debug)]
struct Placement {
    ground: Vec3,
    heading: f64,
}

impl Placement {
    fn of(pose: &Pose) -> Placement {
        let f = facing(pose);
        Placement {
            ground: [pose[0][0], 0.0, pose[0][2]],
            heading: f[0].atan2(f[2]),
        }
    }

    /// `pose` moved from this placement to the origin facing +Z.
    fn to_local(self, pose: &Pose) -> Pose {
        let turn = Quat::from_yaw(-self.heading);
        pose.map(|p| {
            let d = turn.rotate(geom::sub(p, self.ground));
            [d[0], p[1], d[2]]
        })
    }

    /// `pose` moved from the origin facing +Z to this placement.
    fn to_world(self, pose: &Pose) -> Pose {
        let turn = Quat::from_yaw(self.heading);
        pose.map(|p| {
            let d = turn.rotate([p[0], 0.0, p[2]]);
            [d[0] + self.ground[0], p[1], d[2] + self.ground[2]]
        })
    }
}

/// The key poses of a track solved in order (each from the previous one's angles, so a
/// sequence stays consistent), with the constraints the solver could not meet in words.
fn solve_keys(track: &PostureTrack, chained: bool) -> (Vec<Pose>, Vec<String>) {
    let mut previous: Option<Angles> = None;
    let mut poses = Vec::with_capacity(track.keys.len());
    let mut notes = Vec::new();
    for (i, k) in track.keys.iter().enumerate() {
        let solved = solve(&k.script, previous.as_ref());
        if !solved.unmet.is_empty() {
            let missed: Vec<String> = solved.unmet.iter().map(|c| c.to_string()).collect();
            notes.push(format!(
                "key pose {} ({}) could not show: {}",
                i + 1,
                k.script.name.as_deref().unwrap_or("posture"),
                missed.join("; ")
            ));
        }
        if chained {
            previous = Some(solved.angles);
        }
        poses.push(solved.pose);
    }
    (poses, notes)
}

/// Frames (counted from the first key) at the middle of each key's hold, with the index of the
/// track key it is, from the go stage's keys, the track key each shows (`labels`) and the times
/// the go stage reached them.
fn key_frames(keys: &[KeyPose], labels: &[Option<usize>], reached: &[f64]) -> Vec<(usize, usize)> {
    keys.iter()
        .zip(reached)
        .zip(labels)
        .filter_map(|((k, t), key)| key.map(|i| (((t + k.hold / 2.0) * FPS).round() as usize, i)))
        .collect()
}

/// What the review of a laid track found: per key pose checked, its frame and the
/// constraints the describer does not read there.
struct KeyReview {
    misses: Vec<(usize, usize, Vec<super::script::Constraint>)>,
}

impl KeyReview {
    fn count(&self) -> usize {
        self.misses.iter().map(|(_, _, m)| m.len()).sum()
    }
}

fn review_keys(motion: &[Pose], track: &PostureTrack, checks: &[(usize, usize)]) -> KeyReview {
    let floor = crate::posecodes::floor_height(motion);
    // Held on some parts, a key pose's constraints on the rest of the body (its level, the
    // legs under held arms) describe the generated motion, not the posture.
    let held: Vec<usize> = track
        .parts
        .iter()
        .flat_map(|p| p.limb_joints().iter().copied())
        .chain(track.whole_body().then_some(0..22).into_iter().flatten())
        .collect();
    let misses = checks
        .iter()
        .filter_map(|&(frame, key)| {
            let pose = motion.get(frame)?;
            let unmet: Vec<_> = track.keys[key]
                .script
                .unmet(pose, floor)
                .into_iter()
                .filter(|c| c.joints().iter().all(|j| held.contains(j)))
                .collect();
            (!unmet.is_empty()).then_some((frame, key, unmet))
        })
        .collect();
    KeyReview { misses }
}

/// The go stage's keys for a track that starts in `start` (a pose at the origin facing +Z),
/// played as [`PostureTrack::played`] says, with transitions and holds scaled so that the track
/// fills `seconds`: spare time lengthens the holds (or, with none, the transitions), missing
/// time shortens everything. With each key, the track key it shows (`None` for the start and
/// the ways back to it).
fn go_keys(
    track: &PostureTrack,
    start: Pose,
    solved: &[Pose],
    seconds: f64,
) -> (Vec<KeyPose>, Vec<Option<usize>>) {
    let (hold_scale, move_scale) = track.time_scales(seconds);
    let mut keys = vec![KeyPose::new(start, 0.0, 0.0)];
    let labels = std::iter::once(None).chain(track.played()).collect();
    for played in track.played() {
        let (moving, hold) = track.timing(played);
        let key = KeyPose::new(
            played.map_or(start, |i| solved[i]),
            moving * move_scale,
            hold * hold_scale,
        );
        keys.push(match played.map(|i| &track.keys[i]) {
            Some(k) => KeyPose {
                turn_deg: k.turn_deg,
                travel: k.travel,
                motion: match k.jump_m {
                    Some(apex_m) => Transition::Flight { apex_m },
                    None => Transition::Ease,
                },
                ..key
            },
            None => key,
        });
    }
    (keys, labels)
}

/// Lays posture tracks over a motion (world joints, 20 fps) and returns the new motion with
/// notes (key poses that could not be met in full, tracks that needed more time than their
/// frames). Spans are taken in order of their first frame; a whole-body span may change the
/// motion's length when its key poses need more time than the span has, and later spans move
/// with it. With `bridges`, posture segments get down to the floor and up again through them.
pub fn lay_tracks(
    base: &[Pose],
    spans: &[TrackSpan<'_>],
    bridges: Option<&Bridges>,
) -> (Vec<Pose>, Vec<String>) {
    let mut out = base.to_vec();
    let mut notes = Vec::new();
    let mut spans = spans.to_vec();
    spans.sort_by_key(|s| s.frames.start);
    let mut shift: isize = 0;
    // A posture segment followed at once by another ends in its own last key: the next starts
    // from there instead of both passing through the generated frame between them.
    let handed_on: Vec<bool> = (0..spans.len())
        .map(|k| {
            spans
                .get(k + 1)
                .is_some_and(|n| n.track.whole_body() && n.frames.start <= spans[k].frames.end)
        })
        .collect();
    for (span, handed_on) in spans.into_iter().zip(handed_on) {
        if out.is_empty() {
            break;
        }
        let start = (span.frames.start as isize + shift).clamp(0, out.len() as isize - 1) as usize;
        let end =
            ((span.frames.end as isize + shift).max(start as isize + 1) as usize).min(out.len());
        let lay = |chained: bool| {
            let (solved, key_notes) = solve_keys(span.track, chained);
            let mut laid = out.clone();
            let mut lay_notes = key_notes;
            let checks = if span.track.whole_body() {
                let solved = Solved {
                    poses: &solved,
                    bridges,
                    handed_on,
                };
                lay_whole_body(&mut laid, start, end, span.track, solved, &mut lay_notes)
            } else {
                lay_on_parts(&mut laid, start, end, span.track, &solved)
            };
            let review = review_keys(&laid, span.track, &checks);
            (laid, lay_notes, review)
        };
        let (mut laid, mut lay_notes, mut review) = lay(true);
        if review.count() > 0 {
            // The reviewer's correction: key poses solved each on its own rather than from the
            // one before, laid again, kept if the describer then reads more of them back.
            let before = review.count();
            let (again, again_notes, again_review) = lay(false);
            if again_review.count() < before {
                lay_notes = again_notes;
                lay_notes.push(format!(
                    "review: {} constraint(s) of the key poses were not shown; solving each key \
                     pose on its own corrected {}",
                    before,
                    before - again_review.count()
                ));
                laid = again;
                review = again_review;
            }
        }
        for (frame, key, unmet) in &review.misses {
            let missed: Vec<String> = unmet.iter().map(|c| c.to_string()).collect();
            lay_notes.push(format!(
                "review: at {:.1} s, key pose {} ({}) does not show: {}",
                *frame as f64 / FPS,
                key + 1,
                span.track.keys[*key]
                    .script
                    .name
                    .as_deref()
                    .unwrap_or("posture"),
                missed.join("; ")
            ));
        }
        shift += laid.len() as isize - out.len() as isize;
        out = laid;
        notes.extend(lay_notes);
    }
    (out, notes)
}

/// A track's key poses as solved, with the bridges to pass through on the way to the floor.
struct Solved<'a> {
    poses: &'a [Pose],
    bridges: Option<&'a Bridges>,
    /// The next span is a posture segment that starts where this one ends.
    handed_on: bool,
}

fn lay_whole_body(
    out: &mut Vec<Pose>,
    start: usize,
    end: usize,
    track: &PostureTrack,
    solved: Solved<'_>,
    notes: &mut Vec<String>,
) -> Vec<(usize, usize)> {
    // Continue from the last frame before the span (the first frame when the span opens the
    // motion), so the join has no jump.
    let from = start.saturating_sub(1);
    let place = Placement::of(&out[from]);
    // The features' last row leads to one more pose than they describe: a span that reaches it
    // ends the motion, with nothing to join.
    let next = (end + 1 < out.len() && !solved.handed_on).then(|| out[end]);
    // The way out into the next segment's first pose is part of the span.
    let exit = if next.is_some() {
        DEFAULT_TRANSITION_SECONDS
    } else {
        0.0
    };
    let seconds = ((end - from) as f64 / FPS - exit).max(0.5 * (end - from) as f64 / FPS);
    let (mut keys, mut labels) = go_keys(track, place.to_local(&out[from]), solved.poses, seconds);
    if let Some(next) = next {
        // End in the shape the next segment starts with, so it follows without a jump.
        let shape = Placement::of(&next).to_local(&next);
        keys.push(KeyPose::new(shape, DEFAULT_TRANSITION_SECONDS, 0.0));
        labels.push(None);
    }
    let (keys, labels) = bridged(keys, labels, solved.bridges);
    let (local, reached) = go::go_timed(&keys);
    let checks: Vec<(usize, usize)> = key_frames(&keys, &labels, &reached)
        .into_iter()
        .map(|(f, k)| (from + f, k))
        .collect();
    let made: Vec<Pose> = local.iter().map(|p| place.to_world(p)).collect();
    let wanted = end - from;
    if made.len() > wanted + (FPS * 0.25) as usize {
        notes.push(format!(
            "the key poses needed {:.1} s, {:.1} s more than their segment",
            (made.len() - 1) as f64 / FPS,
            (made.len() - 1 - wanted) as f64 / FPS
        ));
    }
    let mut rest: Vec<Pose> = out.split_off(end);
    out.truncate(from + 1);
    out.extend_from_slice(&made[1.min(made.len())..]);
    if let (Some(next), Some(last)) = (next, out.last().copied()) {
        // The rest of the motion moves rigidly so that it continues where the key poses ended.
        let (a, b) = (Placement::of(&next), Placement::of(&last));
        for p in rest.iter_mut() {
            *p = b.to_world(&a.to_local(p));
        }
        // The end key already is the next frame's shape; skip the duplicate.
        if !rest.is_empty() {
            rest.remove(0);
        }
    }
    out.extend(rest);
    checks
}

/// Blends the parts' bones from the generated motion into the track's key poses and back.
fn lay_on_parts(
    out: &mut [Pose],
    start: usize,
    end: usize,
    track: &PostureTrack,
    solved: &[Pose],
) -> Vec<(usize, usize)> {
    let frames = end - start;
    if frames < 2 {
        return Vec::new();
    }
    let place = Placement::of(&out[start]);
    let held_to_end = end >= out.len();
    let holds_legs = track
        .parts
        .iter()
        .any(|p| matches!(p, BodyPart::LeftLeg | BodyPart::RightLeg));
    // Held legs let go by moving back into the generated legs' shape over planted feet (a
    // kneel stands up), not by blending over the floor: the way back is a key of the track.
    let exit = if holds_legs && !held_to_end {
        DEFAULT_TRANSITION_SECONDS.min(frames as f64 / FPS / 3.0)
    } else {
        0.0
    };
    let (mut keys, mut labels) = go_keys(
        track,
        place.to_local(&out[start]),
        solved,
        frames as f64 / FPS - exit,
    );
    if exit > 0.0 {
        keys.push(KeyPose::new(place.to_local(&out[end - 1]), exit, 0.0));
        labels.push(None);
    }
    let (local, reached) = go::go_timed(&keys);
    let checks: Vec<(usize, usize)> = key_frames(&keys, &labels, &reached)
        .into_iter()
        .filter(|(f, _)| *f < frames)
        .map(|(f, k)| (start + f, k))
        .collect();
    let ease_in = (track.keys[0].transition * FPS).max(1.0);
    let ease_out = (RELEASE_SECONDS * FPS).min(frames as f64 / 4.0).max(1.0);
    let bones: Vec<usize> = track
        .parts
        .iter()
        .flat_map(|p| p.limb_joints().iter().copied())
        .collect();
    let offsets = Offsets::reference();
    for f in 0..frames {
        let t = f as f64;
        // Held legs need no blending in or out: the go stage starts from the generated pose
        // and ends in it, over planted feet; blending their rotations as well would drag the
        // feet over the floor.
        let weight = if holds_legs {
            1.0
        } else if held_to_end {
            geom::ease(t / ease_in)
        } else {
            geom::ease(t / ease_in).min(geom::ease((frames as f64 - 1.0 - t) / ease_out))
        };
        if weight <= 0.0 {
            continue;
        }
        let frame = start + f;
        // Held arms are placed where the generated body is now, so they turn with a body that
        // turns; held legs stand where the track started, since they carry the body and their
        // feet stay planted where the go stage put them.
        let placement = if holds_legs {
            place
        } else {
            Placement::of(&out[frame])
        };
        let target = placement.to_world(&local[f.min(local.len() - 1)]);
        let mut rots = skeleton::inverse_kinematics(&[out[frame]], false)[0];
        let goal = skeleton::inverse_kinematics(&[target], false)[0];
        let turned = holds_legs.then_some(0);
        for &j in bones.iter().chain(&turned) {
            rots[j] = rots[j].slerp(goal[j], weight);
        }
        // Held legs move the pelvis as the go stage moves it over their planted feet (back and
        // down into a kneel); held arms leave it where the generated body has it.
        let root = if holds_legs {
            geom::lerp(out[frame][0], target[0], weight)
        } else {
            out[frame][0]
        };
        let mut pose = skeleton::forward_kinematics(&[rots], &offsets, &[root])[0];
        let lowest = |p: &Pose| p.iter().map(|j| j[1]).fold(f64::INFINITY, f64::min);
        // Held legs carry the body: it stands on them as it stood on the generated legs
        // (a kneel held over a standing motion kneels on the floor, not in mid-air). Held arms
        // leave the height alone, unless they would go through the floor.
        let drop = if holds_legs {
            lowest(&pose) - lowest(&out[frame])
        } else {
            lowest(&pose).min(0.0)
        };
        for p in pose.iter_mut() {
            p[1] -= drop;
        }
        out[frame] = pose;
    }
    checks
}
