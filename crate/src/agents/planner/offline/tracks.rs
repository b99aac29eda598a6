//! The body-part tracks of a built-in plan: what the clause rules put on each segment's parts,
//! read back as clips. A part that does the same thing over consecutive segments does it as
//! one clip across them ("holding the T-pose" over a walk and then a run; a T-pose held over
//! two squats), not as one copy per segment that lets go and takes hold again at each join.

use crate::plan::{in_time_order, Clip, Segment};
use crate::posture::library::NamedPosture;
use crate::posture::script::PostureScript;
use crate::posture::track::PostureTrack;
use crate::skeleton::BodyPart;
use std::ops::Range;

/// Takes the held postures and part instructions that run unchanged over two or more
/// consecutive segments off those segments and returns them as clips over the whole run.
/// `clause_of[k]` is the clause segment `k` came from: an instruction is one clip only within
/// a clause (two clauses that each wave wave twice); a held posture is one clip whichever
/// clauses it spans, since holding it on is what both ask.
pub fn clips_across_segments(segments: &mut [Segment], clause_of: &[usize]) -> Vec<Clip> {
    let mut starts = vec![0.0];
    for s in segments.iter() {
        starts.push(starts.last().copied().unwrap_or(0.0) + s.seconds);
    }
    let mut clips = Vec::new();
    let held = |s: &Segment| {
        s.postures
            .clone()
            .filter(|t| !t.whole_body() && t.within.is_none())
    };
    let mut k = 0;
    while k < segments.len() {
        let Some(track) = held(&segments[k]) else {
            k += 1;
            continue;
        };
        let run = segments[k..]
            .iter()
            .take_while(|s| held(s).as_ref() == Some(&track))
            .count();
        if run > 1 {
            for s in &mut segments[k..k + run] {
                s.postures = None;
            }
            clips.push(Clip {
                parts: track.parts.clone(),
                text: posture_names(track.keys.iter().map(|key| &key.script)),
                start: starts[k],
                end: starts[k + run],
                postures: Some(track),
            });
        }
        k += run;
    }
    for part in BodyPart::ALL {
        let mut k = 0;
        while k < segments.len() {
            let Some(text) = segments[k].parts.get(part).map(str::to_string) else {
                k += 1;
                continue;
            };
            let run = (k..segments.len())
                .take_while(|&j| {
                    segments[j].parts.get(part) == Some(text.as_str())
                        && clause_of.get(j) == clause_of.get(k)
                })
                .count();
            if run > 1 {
                for s in &mut segments[k..k + run] {
                    s.parts.set(part, None);
                }
                let (start, end) = (starts[k], starts[k + run]);
                // Parts asked the same thing over the same run move as one clip ("both arms").
                match clips.iter_mut().find(|c: &&mut Clip| {
                    c.postures.is_none() && c.text == text && c.start == start && c.end == end
                }) {
                    Some(clip) => clip.parts.push(part),
                    None => clips.push(Clip {
                        parts: vec![part],
                        text,
                        start,
                        end,
                        postures: None,
                    }),
                }
            }
            k += run;
        }
    }
    in_time_order(&mut clips);
    clips
}

/// The limb poses read from a clause's words ([`super::limb_poses`]) as clips holding them,
/// each over the segments its clause made (`held`: their indices; those past the plan's end
/// are gone with them).
pub fn held_clips(segments: &[Segment], held: &[(Range<usize>, NamedPosture)]) -> Vec<Clip> {
    let mut starts = vec![0.0];
    for s in segments {
        starts.push(starts.last().copied().unwrap_or(0.0) + s.seconds);
    }
    held.iter()
        .filter_map(|(range, pose)| {
            let end = range.end.min(segments.len());
            (range.start < end).then(|| Clip {
                parts: pose.parts.clone(),
                text: pose.name.clone(),
                start: starts[range.start],
                end: starts[end],
                postures: Some(PostureTrack::holding(
                    pose.parts.clone(),
                    pose.script.clone(),
                )),
            })
        })
        .collect()
}

/// The names of key poses in order, each once, as a clip's text ("T-pose").
fn posture_names<'a>(scripts: impl Iterator<Item = &'a PostureScript>) -> String {
    let mut names: Vec<String> = Vec::new();
    for script in scripts {
        let name = script.name.clone().unwrap_or_else(|| script.in_words());
        if !names.contains(&name) {
            names.push(name);
        }
    }
    names.join(", ")
}
