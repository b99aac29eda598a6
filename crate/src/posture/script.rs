//! Posture scripts: one key pose written as constraints in the pose-code vocabulary of the
//! describer (`crate::posecodes`), so that an LLM can write them, a person can read them and
//! the describer can check a pose against them.
//!
//! A script in JSON:
//!
//! ```json
//! {"name": "T-pose", "hold": 1.0, "constraints": [
//!   {"kind": "bend", "joint": "left_elbow", "is": "straight"},
//!   {"kind": "orientation", "limb": "left_upper_arm", "is": "horizontal"},
//!   {"kind": "distance", "a": "left_hand", "b": "right_hand", "is": "wide"},
//!   {"kind": "level", "is": "standing"}]}
//! ```
//!
//! [`PostureScript::parse`] reads it with errors a person or an LLM can act on (which
//! constraint, which word, what is allowed), and reports constraints that contradict each other
//! or that no body can meet.

use crate::geom;
use crate::posecodes::{
    self, angle_from_vertical_deg, body_level, relative_offset, torso_lean, torso_twist, Bend,
    BodyPoint, Distance, Lean, Limb, Orientation, PelvisLevel, Relation, Support, Twist,
};
use crate::skeleton::{joint, Pose, PARENTS, REFERENCE_BONE_LENGTHS};
use serde::{Deserialize, Serialize};
use std::fmt;

/// Most constraints a script may have: enough for any pose (a fully specified one uses about
/// 25), few enough that a runaway LLM reply is refused rather than solved.
pub const MAX_CONSTRAINTS: usize = 40;
/// Longest hold of one key pose, seconds.
pub const MAX_HOLD_SECONDS: f64 = 10.0;
/// Hold of a key pose when the script does not say, seconds.
pub const DEFAULT_HOLD_SECONDS: f64 = 0.5;
/// Longest name, characters.
pub const MAX_NAME_CHARS: usize = 60;

/// A knee or elbow that bends.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Hinge {
    LeftElbow,
    RightElbow,
    LeftKnee,
    RightKnee,
}

impl Hinge {
    /// Every hinge, in the order of the schema.
    pub const ALL: [Hinge; 4] = [
        Hinge::LeftElbow,
        Hinge::RightElbow,
        Hinge::LeftKnee,
        Hinge::RightKnee,
    ];

    /// The three joints whose inner angle at the middle one is the bend.
    pub fn joints(self) -> [usize; 3] {
        match self {
            Hinge::LeftElbow => [joint::L_SHOULDER, joint::L_ELBOW, joint::L_WRIST],
            Hinge::RightElbow => [joint::R_SHOULDER, joint::R_ELBOW, joint::R_WRIST],
            Hinge::LeftKnee => [joint::L_HIP, joint::L_KNEE, joint::L_ANKLE],
            Hinge::RightKnee => [joint::R_HIP, joint::R_KNEE, joint::R_ANKLE],
        }
    }

    /// Words for the hinge ("the left elbow").
    pub fn as_str(self) -> &'static str {
        match self {
            Hinge::LeftElbow => "the left elbow",
            Hinge::RightElbow => "the right elbow",
            Hinge::LeftKnee => "the left knee",
            Hinge::RightKnee => "the right knee",
        }
    }

    /// Inner angle of the hinge in degrees (180 = straight).
    pub fn angle_deg(self, pose: &Pose) -> f64 {
        let [a, b, c] = self.joints();
        posecodes::joint_angle_deg(pose[a], pose[b], pose[c])
    }
}

/// One thing a key pose must show, in the describer's categories.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum Constraint {
    /// How bent an elbow or knee is.
    Bend { joint: Hinge, is: Bend },
    /// How far apart two body points are.
    Distance {
        a: BodyPoint,
        b: BodyPoint,
        is: Distance,
    },
    /// Where `a` is relative to `b` (above, in front of, to the left of, …).
    Relation {
        a: BodyPoint,
        b: BodyPoint,
        is: Relation,
    },
    /// A limb's angle to the vertical.
    Orientation { limb: Limb, is: Orientation },
    /// Whether a foot, knee, hand or the pelvis touches the ground.
    Contact { point: Support, on_ground: bool },
    /// Which way the torso leans.
    Lean { is: Lean },
    /// Whether the shoulders are turned against the hips.
    Twist { is: Twist },
    /// How high the body is: standing, crouching, kneeling, sitting on the floor, lying.
    Level { is: PelvisLevel },
}

impl Constraint {
    /// Whether `pose` (world positions, metres, on a floor at height `floor`) meets the
    /// constraint, read by the describer.
    pub fn holds(&self, pose: &Pose, floor: f64) -> bool {
        match *self {
            Constraint::Bend { joint, is } => Bend::from_angle(joint.angle_deg(pose)) == is,
            Constraint::Distance { a, b, is } => {
                Distance::from_metres(geom::dist(pose[a.joint()], pose[b.joint()])) == is
            }
            Constraint::Relation { a, b, is } => {
                is.holds_for(relative_offset(pose, a, b, is.axis()))
            }
            Constraint::Orientation { limb, is } => Orientation::of(limb.vector(pose)) == is,
            Constraint::Contact { point, on_ground } => point.on_ground(pose, floor) == on_ground,
            Constraint::Lean { is } => torso_lean(pose) == is,
            Constraint::Twist { is } => torso_twist(pose) == is,
            Constraint::Level { is } => body_level(pose, floor) == is,
        }
    }

    /// The skeleton joints the constraint reads; lean, twist and level read the trunk and
    /// legs (pelvis, hips, neck, shoulders, knees).
    pub fn joints(&self) -> Vec<usize> {
        match *self {
            Constraint::Bend { joint, .. } => joint.joints().to_vec(),
            Constraint::Distance { a, b, .. } | Constraint::Relation { a, b, .. } => {
                vec![a.joint(), b.joint()]
            }
            Constraint::Orientation { limb, .. } => {
                let (a, b) = limb.joints();
                vec![a, b]
            }
            Constraint::Contact { point, .. } => match point {
                Support::LeftFoot => vec![joint::L_ANKLE, joint::L_FOOT],
                Support::RightFoot => vec![joint::R_ANKLE, joint::R_FOOT],
                Support::LeftKnee => vec![joint::L_KNEE],
                Support::RightKnee => vec![joint::R_KNEE],
                Support::LeftHand => vec![joint::L_WRIST],
                Support::RightHand => vec![joint::R_WRIST],
                Support::Pelvis => vec![joint::PELVIS],
            },
            Constraint::Lean { .. } | Constraint::Twist { .. } | Constraint::Level { .. } => vec![
                joint::PELVIS,
                joint::L_HIP,
                joint::R_HIP,
                joint::NECK,
                joint::L_SHOULDER,
                joint::R_SHOULDER,
                joint::L_KNEE,
                joint::R_KNEE,
            ],
        }
    }

    /// What the constraint is about, so that two constraints on the same subject can be
    /// compared: the same subject with different values is a contradiction.
    fn subject(&self) -> Subject {
        match *self {
            Constraint::Bend { joint, .. } => Subject::Bend(joint),
            Constraint::Distance { a, b, .. } => Subject::Distance(a.min(b), a.max(b)),
            Constraint::Relation { a, b, is } => {
                let (a, b, axis) = if a <= b {
                    (a, b, is.axis())
                } else {
                    (b, a, is.axis())
                };
                Subject::Relation(a, b, axis)
            }
            Constraint::Orientation { limb, .. } => Subject::Orientation(limb),
            Constraint::Contact { point, .. } => Subject::Contact(point),
            Constraint::Lean { .. } => Subject::Lean,
            Constraint::Twist { .. } => Subject::Twist,
            Constraint::Level { .. } => Subject::Level,
        }
    }

    /// The constraint with its two points in a canonical order (relations turned into their
    /// converse), so that "a above b" and "b below a" compare equal.
    fn canonical(self) -> Constraint {
        match self {
            Constraint::Distance { a, b, is } if b < a => Constraint::Distance { a: b, b: a, is },
            Constraint::Relation { a, b, is } if b < a => Constraint::Relation {
                a: b,
                b: a,
                is: is.converse(),
            },
            other => other,
        }
    }
}

impl fmt::Display for Constraint {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            Constraint::Bend { joint, is } => write!(f, "{} is {}", joint.as_str(), is.as_str()),
            Constraint::Distance { a, b, is } => match is {
                Distance::Close => write!(f, "{} and {} are close", a.as_str(), b.as_str()),
                Distance::ShoulderWidth => {
                    write!(
                        f,
                        "{} and {} are shoulder width apart",
                        a.as_str(),
                        b.as_str()
                    )
                }
                Distance::Spread => write!(f, "{} and {} are spread apart", a.as_str(), b.as_str()),
                Distance::Wide => write!(f, "{} and {} are wide apart", a.as_str(), b.as_str()),
            },
            Constraint::Relation { a, b, is } => {
                write!(f, "{} is {} {}", a.as_str(), is.as_str(), b.as_str())
            }
            Constraint::Orientation { limb, is } => {
                write!(f, "{} is {}", limb.as_str(), is.as_str())
            }
            Constraint::Contact { point, on_ground } => write!(
                f,
                "{} {} the ground",
                point.as_str(),
                if on_ground { "touches" } else { "is off" }
            ),
            Constraint::Lean { is } => write!(f, "the torso {}", is.as_str()),
            Constraint::Twist { is } => write!(f, "the torso {}", is.as_str()),
            Constraint::Level { is } => write!(f, "the body is {}", is.as_str()),
        }
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Subject {
    Bend(Hinge),
    Distance(BodyPoint, BodyPoint),
    Relation(BodyPoint, BodyPoint, usize),
    Orientation(Limb),
    Contact(Support),
    Lean,
    Twist,
    Level,
}

/// One key pose: what it must show, and how long it is held once reached.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct PostureScript {
    /// A short name for people ("T-pose"); not used to solve.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub name: Option<String>,
    /// Seconds the pose is held once reached (0 to [`MAX_HOLD_SECONDS`]).
    #[serde(default = "default_hold")]
    pub hold: f64,
    /// What the pose must show; anything left open takes the natural rest pose (or the
    /// previous key pose).
    pub constraints: Vec<Constraint>,
}

fn default_hold() -> f64 {
    DEFAULT_HOLD_SECONDS
}

/// Why a posture script was refused: each message names the constraint (1-based, as a person
/// counts) and says what is allowed.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum ScriptError {
    #[error("the posture script is not JSON of the expected shape: {0}")]
    Shape(String),
    #[error("constraint {index} ({text}): {reason}")]
    Constraint {
        index: usize,
        text: String,
        reason: String,
    },
    #[error("a posture script needs 1 to {MAX_CONSTRAINTS} constraints, this one has {0}")]
    Count(usize),
    #[error("hold must be a number of seconds from 0 to {MAX_HOLD_SECONDS}, got {0}")]
    Hold(f64),
    #[error("the name is longer than {MAX_NAME_CHARS} characters")]
    Name,
    #[error(
        "constraints {first} and {second} contradict each other: {first_text}, but {second_text}"
    )]
    Contradiction {
        first: usize,
        second: usize,
        first_text: String,
        second_text: String,
    },
    #[error("constraint {index} cannot hold on any body: {reason}")]
    Impossible { index: usize, reason: String },
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct ScriptFields {
    #[serde(default)]
    name: Option<String>,
    #[serde(default = "default_hold")]
    hold: f64,
    constraints: Vec<serde_json::Value>,
}

impl PostureScript {
    /// The same pose on the other side of the body: every left and right swapped (joints,
    /// limbs, contacts, "to the left of", a lean or a twist to the left), so "pointing
    /// forward" with the right arm becomes the left arm's.
    ///
    /// Done on the script's own JSON form, where each of these is a `left`/`right` name
    /// (`left_elbow`, `right_of`, `left`): one swap covers every kind of constraint, present
    /// and future, where a table per kind would have to be kept in step with the enums.
    pub fn mirrored(&self) -> PostureScript {
        fn swap(value: &mut serde_json::Value) {
            match value {
                serde_json::Value::String(s) => {
                    if let Some(rest) = s.strip_prefix("left") {
                        *s = format!("right{rest}");
                    } else if let Some(rest) = s.strip_prefix("right") {
                        *s = format!("left{rest}");
                    }
                }
                serde_json::Value::Array(items) => items.iter_mut().for_each(swap),
                serde_json::Value::Object(fields) => fields
                    .iter_mut()
                    .filter(|(k, _)| k.as_str() != "name")
                    .for_each(|(_, v)| swap(v)),
                _ => {}
            }
        }
        let mut value = serde_json::to_value(self).expect("a script is plain data");
        swap(&mut value);
        serde_json::from_value(value).expect("the mirror of a script is a script")
    }

    /// Reads a script from JSON text and checks it (see [`PostureScript::check`]).
    pub fn parse(text: &str) -> Result<PostureScript, ScriptError> {
        let value: serde_json::Value =
            serde_json::from_str(text).map_err(|e| ScriptError::Shape(e.to_string()))?;
        PostureScript::from_value(value)
    }

    /// Reads a script from a parsed JSON value and checks it. Each constraint is read on its
    /// own so that an error names the one that is wrong.
    pub fn from_value(value: serde_json::Value) -> Result<PostureScript, ScriptError> {
        let fields: ScriptFields =
            serde_json::from_value(value).map_err(|e| ScriptError::Shape(e.to_string()))?;
        if fields.constraints.is_empty() || fields.constraints.len() > MAX_CONSTRAINTS {
            return Err(ScriptError::Count(fields.constraints.len()));
        }
        let constraints = fields
            .constraints
            .into_iter()
            .enumerate()
            .map(|(i, v)| {
                let text = short_json(&v);
                serde_json::from_value::<Constraint>(v).map_err(|e| ScriptError::Constraint {
                    index: i + 1,
                    text,
                    reason: e.to_string(),
                })
            })
            .collect::<Result<Vec<_>, _>>()?;
        PostureScript {
            name: fields.name,
            hold: fields.hold,
            constraints,
        }
        .check()
    }

    /// Checks a script built in code or read from JSON: hold and name in bounds, no two
    /// constraints on the same subject disagreeing, none asking what no body can do (two points
    /// further apart than the bones between them reach, a point related to itself, a level its
    /// contacts rule out).
    pub fn check(self) -> Result<PostureScript, ScriptError> {
        if !(0.0..=MAX_HOLD_SECONDS).contains(&self.hold) {
            return Err(ScriptError::Hold(self.hold));
        }
        if self
            .name
            .as_ref()
            .is_some_and(|n| n.chars().count() > MAX_NAME_CHARS)
        {
            return Err(ScriptError::Name);
        }
        if self.constraints.is_empty() || self.constraints.len() > MAX_CONSTRAINTS {
            return Err(ScriptError::Count(self.constraints.len()));
        }
        for (i, c) in self.constraints.iter().enumerate() {
            if let Some(reason) = impossible(c) {
                return Err(ScriptError::Impossible {
                    index: i + 1,
                    reason,
                });
            }
            for (j, d) in self.constraints.iter().enumerate().take(i) {
                if c.subject() == d.subject() && c.canonical() != d.canonical() {
                    return Err(ScriptError::Contradiction {
                        first: j + 1,
                        second: i + 1,
                        first_text: d.to_string(),
                        second_text: c.to_string(),
                    });
                }
            }
        }
        if let Some((first, second)) = level_against_contacts(&self.constraints) {
            return Err(ScriptError::Contradiction {
                first: first + 1,
                second: second + 1,
                first_text: self.constraints[first].to_string(),
                second_text: self.constraints[second].to_string(),
            });
        }
        Ok(self)
    }

    /// The constraints `pose` fails, read by the describer on a floor at `floor` metres.
    pub fn unmet(&self, pose: &Pose, floor: f64) -> Vec<Constraint> {
        self.constraints
            .iter()
            .filter(|c| !c.holds(pose, floor))
            .copied()
            .collect()
    }

    /// The script in words, one clause per constraint ("the left elbow is straight; …").
    pub fn in_words(&self) -> String {
        let clauses: Vec<String> = self.constraints.iter().map(|c| c.to_string()).collect();
        clauses.join("; ")
    }
}

fn short_json(v: &serde_json::Value) -> String {
    let text = v.to_string();
    if text.chars().count() > 120 {
        format!("{}…", text.chars().take(120).collect::<String>())
    } else {
        text
    }
}

/// The longest distance (metres) two joints can be apart on the reference skeleton: the bones
/// along the path between them, stretched straight.
pub fn reach_m(a: usize, b: usize) -> f64 {
    let path = |mut j: usize| {
        let mut out = vec![j];
        while let Some(p) = PARENTS[j] {
            out.push(p);
            j = p;
        }
        out
    };
    let (pa, pb) = (path(a), path(b));
    let common = pa.iter().find(|j| pb.contains(j)).copied().unwrap_or(0);
    let length = |p: &[usize]| {
        p.iter()
            .take_while(|&&j| j != common)
            .map(|&j| REFERENCE_BONE_LENGTHS[j])
            .sum::<f64>()
    };
    length(&pa) + length(&pb)
}

fn impossible(c: &Constraint) -> Option<String> {
    match *c {
        Constraint::Distance { a, b, .. } | Constraint::Relation { a, b, .. } if a == b => {
            Some(format!("{} is compared with itself", a.as_str()))
        }
        Constraint::Distance { a, b, is } => {
            let reach = reach_m(a.joint(), b.joint());
            let least = match is {
                Distance::Close => 0.0,
                Distance::ShoulderWidth => posecodes::CLOSE_MAX_M,
                Distance::Spread => posecodes::SHOULDER_WIDTH_MAX_M,
                Distance::Wide => posecodes::SPREAD_MAX_M,
            };
            (reach <= least + 0.02).then(|| {
                format!(
                    "{} and {} are at most {reach:.2} m apart on this body, and '{}' needs more \
                     than {least:.2} m",
                    a.as_str(),
                    b.as_str(),
                    is.as_str()
                )
            })
        }
        _ => None,
    }
}

/// A level that the script's own contacts rule out: kneeling with both knees off the ground,
/// sitting with the pelvis off it, standing with a knee or the pelvis down. Returns the indices
/// of the level and the contact.
fn level_against_contacts(constraints: &[Constraint]) -> Option<(usize, usize)> {
    let (li, level) = constraints.iter().enumerate().find_map(|(i, c)| match c {
        Constraint::Level { is } => Some((i, *is)),
        _ => None,
    })?;
    let contact = |point: Support| {
        constraints.iter().enumerate().find_map(|(i, c)| match *c {
            Constraint::Contact {
                point: p,
                on_ground,
            } if p == point => Some((i, on_ground)),
            _ => None,
        })
    };
    let knees = [contact(Support::LeftKnee), contact(Support::RightKnee)];
    let pelvis = contact(Support::Pelvis);
    match level {
        PelvisLevel::Kneeling => match knees {
            [Some((a, false)), Some((_, false))] => Some((li, a)),
            _ => None,
        },
        // The describer reads a knee on the ground as kneeling before it looks at the pelvis.
        PelvisLevel::Sitting => match pelvis {
            Some((i, false)) => Some((li, i)),
            _ => knees
                .iter()
                .flatten()
                .find(|(_, down)| *down)
                .map(|(i, _)| (li, *i)),
        },
        PelvisLevel::Standing | PelvisLevel::Crouching => knees
            .iter()
            .flatten()
            .chain(pelvis.iter())
            .find(|(_, down)| *down)
            .map(|(i, _)| (li, *i)),
        PelvisLevel::Lying => None,
    }
}

/// Angle of a limb from the vertical in degrees, as the describer reads orientation.
pub fn limb_angle_deg(limb: Limb, pose: &Pose) -> f64 {
    angle_from_vertical_deg(limb.vector(pose))
}

/// The JSON schema of a posture script (draft 2020-12), built from the same word lists the
/// parser accepts: what the LLM planner is asked to follow and what the page documents.
pub fn schema() -> serde_json::Value {
    use serde_json::json;
    fn words<T: Serialize>(items: &[T]) -> serde_json::Value {
        serde_json::Value::Array(
            items
                .iter()
                .map(|i| serde_json::to_value(i).expect("a word list serialises"))
                .collect(),
        )
    }
    let points = words(&BodyPoint::ALL);
    let variant = |kind: &str, props: serde_json::Value| {
        let mut properties = props.as_object().cloned().unwrap_or_default();
        let mut required: Vec<String> = properties.keys().cloned().collect();
        properties.insert("kind".into(), json!({"const": kind}));
        required.insert(0, "kind".into());
        json!({"type": "object", "properties": properties, "required": required,
               "additionalProperties": false})
    };
    json!({
        "$schema": "https://json-schema.org/draft/2020-12/schema",
        "title": "posture script",
        "type": "object",
        "properties": {
            "name": {"type": "string", "maxLength": MAX_NAME_CHARS},
            "hold": {"type": "number", "minimum": 0, "maximum": MAX_HOLD_SECONDS},
            "constraints": {
                "type": "array", "minItems": 1, "maxItems": MAX_CONSTRAINTS,
                "items": {"oneOf": [
                    variant("bend", json!({"joint": {"enum": words(&Hinge::ALL)},
                        "is": {"enum": words(&Bend::ALL)}})),
                    variant("distance", json!({"a": {"enum": points}, "b": {"enum": points},
                        "is": {"enum": words(&Distance::ALL)}})),
                    variant("relation", json!({"a": {"enum": points}, "b": {"enum": points},
                        "is": {"enum": words(&Relation::ALL)}})),
                    variant("orientation", json!({"limb": {"enum": words(&Limb::ALL)},
                        "is": {"enum": words(&Orientation::ALL)}})),
                    variant("contact", json!({"point": {"enum": words(&Support::ALL)},
                        "on_ground": {"type": "boolean"}})),
                    variant("lean", json!({"is": {"enum": words(&Lean::ALL)}})),
                    variant("twist", json!({"is": {"enum": words(&Twist::ALL)}})),
                    variant("level", json!({"is": {"enum": words(&PelvisLevel::ALL)}})),
                ]}
            }
        },
        "required": ["constraints"],
        "additionalProperties": false
    })
}

/// Pairs of points whose distance the describer reports for a whole pose: hands with each
/// other and the head, shoulders, hips and feet; feet and knees with each other; elbows.
pub const DESCRIBED_DISTANCES: [(BodyPoint, BodyPoint); 10] = [
    (BodyPoint::LeftHand, BodyPoint::RightHand),
    (BodyPoint::LeftFoot, BodyPoint::RightFoot),
    (BodyPoint::LeftKnee, BodyPoint::RightKnee),
    (BodyPoint::LeftElbow, BodyPoint::RightElbow),
    (BodyPoint::LeftHand, BodyPoint::Head),
    (BodyPoint::RightHand, BodyPoint::Head),
    (BodyPoint::LeftHand, BodyPoint::LeftFoot),
    (BodyPoint::RightHand, BodyPoint::RightFoot),
    (BodyPoint::LeftHand, BodyPoint::LeftHip),
    (BodyPoint::RightHand, BodyPoint::RightHip),
];

/// Pairs whose relation (height, depth and side) the describer reports for a whole pose.
pub const DESCRIBED_RELATIONS: [(BodyPoint, BodyPoint); 12] = [
    (BodyPoint::LeftHand, BodyPoint::Head),
    (BodyPoint::RightHand, BodyPoint::Head),
    (BodyPoint::LeftHand, BodyPoint::LeftShoulder),
    (BodyPoint::RightHand, BodyPoint::RightShoulder),
    (BodyPoint::LeftHand, BodyPoint::Pelvis),
    (BodyPoint::RightHand, BodyPoint::Pelvis),
    (BodyPoint::LeftHand, BodyPoint::RightHand),
    (BodyPoint::LeftFoot, BodyPoint::RightFoot),
    (BodyPoint::LeftKnee, BodyPoint::Pelvis),
    (BodyPoint::RightKnee, BodyPoint::Pelvis),
    (BodyPoint::Head, BodyPoint::Pelvis),
    (BodyPoint::LeftElbow, BodyPoint::LeftShoulder),
];

/// Everything the describer reads off a pose on a floor at `floor` metres, as constraints: the
/// bends, the orientation of every limb, the contacts, lean, twist and level, and the distance
/// and relations of the pairs in [`DESCRIBED_DISTANCES`] and [`DESCRIBED_RELATIONS`]. A script
/// made of any subset of them is met by the pose.
pub fn describe_pose(pose: &Pose, floor: f64) -> Vec<Constraint> {
    let mut out = Vec::new();
    for joint in Hinge::ALL {
        out.push(Constraint::Bend {
            joint,
            is: Bend::from_angle(joint.angle_deg(pose)),
        });
    }
    for limb in Limb::ALL {
        out.push(Constraint::Orientation {
            limb,
            is: Orientation::of(limb.vector(pose)),
        });
    }
    for point in Support::ALL {
        out.push(Constraint::Contact {
            point,
            on_ground: point.on_ground(pose, floor),
        });
    }
    out.push(Constraint::Lean {
        is: torso_lean(pose),
    });
    out.push(Constraint::Twist {
        is: torso_twist(pose),
    });
    out.push(Constraint::Level {
        is: body_level(pose, floor),
    });
    for (a, b) in DESCRIBED_DISTANCES {
        out.push(Constraint::Distance {
            a,
            b,
            is: Distance::from_metres(geom::dist(pose[a.joint()], pose[b.joint()])),
        });
    }
    for (a, b) in DESCRIBED_RELATIONS {
        for candidates in [
            [Relation::Above, Relation::Below, Relation::LevelWith],
            [Relation::InFrontOf, Relation::Behind, Relation::Behind],
            [Relation::LeftOf, Relation::RightOf, Relation::RightOf],
        ] {
            let offset = relative_offset(pose, a, b, candidates[0].axis());
            if let Some(is) = candidates.into_iter().find(|r| r.holds_for(offset)) {
                out.push(Constraint::Relation { a, b, is });
            }
        }
    }
    out
}
