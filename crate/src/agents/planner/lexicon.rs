//! The words the built-in planner understands, and the caption phrases it answers with.
//!
//! Every phrase it writes uses only words of the training captions (checked by a test
//! against `static/models/vocabulary.json`), so the motion model reads text it has seen.
//!
//! Two sets of actions: the Bandai Namco actions every shipped model knows, and the actions of
//! the motion-capture sources of dataset v2 (HDM05, CMU, DeepMimic), which the planner uses
//! only when the loaded model's vocabulary lists them ([`Repertoire`]).

use crate::dataset::Vocabulary;

/// Which arm or arms a gesture uses, or which hand or leg a one-limb action.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Side {
    Left,
    Right,
    Both,
}

impl Side {
    fn words(self) -> &'static str {
        match self {
            Side::Left => "the left hand",
            Side::Right => "the right hand",
            Side::Both => "both hands",
        }
    }

    /// The side of a one-limb action: "left", or "right" (also for `Both`, which no one-limb
    /// action has).
    fn one(self) -> &'static str {
        match self {
            Side::Left => "left",
            Side::Right | Side::Both => "right",
        }
    }
}

/// Where a walk goes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Direction {
    Forward,
    Backward,
    Left,
    Right,
    TurnLeft,
    TurnRight,
}

/// A movement the training data holds: the Bandai Namco action labels, then the actions of
/// dataset v2's motion-capture sources (see [`Action::label`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Action {
    Walk(Direction),
    Run,
    Dash,
    Bow,
    Kick,
    Punch,
    /// A punch with one hand ("throws a left punch", as the Bandai Namco captions say it).
    PunchWith(Side),
    Slash,
    Dance,
    Beckon,
    Guide,
    Wave(Side),
    Goodbye,
    Raise(Side),
    /// One squat: down and back up.
    Squat,
    /// A jump in place with both feet.
    Jump,
    /// A jump forward with both feet.
    JumpForward,
    /// Getting down from standing to lying on the floor.
    LieDown,
    /// A front kick with one leg.
    FrontKick(Side),
    /// Kicking a ball (soccer) with one foot.
    KickBall(Side),
    /// Throwing a ball (a basketball throw).
    Throw,
    /// Reaching up high with one hand (taking something from a high shelf).
    ReachUp(Side),
    /// Bending down to put something on the floor with one hand.
    PutDown(Side),
    /// Sneaking forward on tiptoe.
    Sneak,
    /// Circling both arms backward.
    ArmCircles,
    /// The standing exercise bringing each elbow to the opposite knee.
    ElbowToKnee,
    /// Dribbling and shooting a basketball.
    Basketball,
    /// A basketball referee's arm signals.
    RefereeSignals,
    /// Directing traffic with arm signals.
    DirectTraffic,
    /// Washing a window with one hand in circles.
    WashWindow,
    /// Jogging round a circle, turning to the given side.
    JogCircle(Side),
}

/// The actions of dataset v2's motion-capture sources, each side of the one-sided ones.
pub const DATASET_ACTIONS: [Action; 22] = [
    Action::Squat,
    Action::Jump,
    Action::JumpForward,
    Action::LieDown,
    Action::FrontKick(Side::Left),
    Action::FrontKick(Side::Right),
    Action::KickBall(Side::Left),
    Action::KickBall(Side::Right),
    Action::Throw,
    Action::ReachUp(Side::Left),
    Action::ReachUp(Side::Right),
    Action::PutDown(Side::Left),
    Action::PutDown(Side::Right),
    Action::Sneak,
    Action::ArmCircles,
    Action::ElbowToKnee,
    Action::Basketball,
    Action::RefereeSignals,
    Action::DirectTraffic,
    Action::WashWindow,
    Action::JogCircle(Side::Left),
    Action::JogCircle(Side::Right),
];

impl Action {
    /// Moves the whole body through space.
    pub fn is_locomotion(self) -> bool {
        matches!(
            self,
            Action::Walk(_) | Action::Run | Action::Dash | Action::Sneak | Action::JogCircle(_)
        )
    }

    /// Made with the legs and the body while the arms only swing along, so the arms can hold
    /// a posture over it (a squat in a T-pose). Locomotion is this too.
    pub fn frees_arms(self) -> bool {
        self.is_locomotion()
            || matches!(
                self,
                Action::Squat
                    | Action::Jump
                    | Action::JumpForward
                    | Action::FrontKick(_)
                    | Action::KickBall(_)
            )
    }

    /// The action label of dataset v2 ("squat", "kick-left-leg"), for the actions the model
    /// knows only when its vocabulary lists that label; `None` for the Bandai Namco actions,
    /// which every model knows.
    pub fn label(self) -> Option<String> {
        Some(match self {
            Action::Squat => "squat".into(),
            Action::Jump => "jump".into(),
            Action::JumpForward => "jump-forward".into(),
            Action::LieDown => "lie-down".into(),
            Action::FrontKick(side) => format!("kick-{}-leg", side.one()),
            Action::KickBall(side) => format!("kick-ball-{}-leg", side.one()),
            Action::Throw => "throw".into(),
            Action::ReachUp(side) => format!("reach-up-{}-hand", side.one()),
            Action::PutDown(side) => format!("put-down-{}-hand", side.one()),
            Action::Sneak => "sneak".into(),
            Action::ArmCircles => "arm-circles".into(),
            Action::ElbowToKnee => "elbow-to-knee".into(),
            Action::Basketball => "basketball".into(),
            Action::RefereeSignals => "referee-signals".into(),
            Action::DirectTraffic => "direct-traffic".into(),
            Action::WashWindow => "wash-window".into(),
            Action::JogCircle(side) => format!("jog-circle-{}", side.one()),
            _ => return None,
        })
    }

    /// Done with the arms alone, so it can ride on another motion as a part edit.
    pub fn is_gesture(self) -> bool {
        matches!(
            self,
            Action::Wave(_) | Action::Raise(_) | Action::Goodbye | Action::Beckon | Action::Guide
        )
    }

    /// The arms a gesture uses, or that an action of dataset v2 is made with, so no gesture
    /// rides on them ("reaches up with the left hand", "directs traffic"); none for the other
    /// whole-body actions.
    pub fn arms(self) -> &'static [crate::skeleton::BodyPart] {
        use crate::skeleton::BodyPart::{LeftArm, RightArm};
        match self {
            Action::Wave(Side::Left)
            | Action::Raise(Side::Left)
            | Action::ReachUp(Side::Left)
            | Action::PutDown(Side::Left) => &[LeftArm],
            Action::Wave(Side::Both)
            | Action::Raise(Side::Both)
            | Action::Throw
            | Action::ArmCircles
            | Action::ElbowToKnee
            | Action::Basketball
            | Action::RefereeSignals
            | Action::DirectTraffic
            | Action::WashWindow => &[LeftArm, RightArm],
            Action::Wave(_)
            | Action::Raise(_)
            | Action::Goodbye
            | Action::Beckon
            | Action::Guide
            | Action::ReachUp(_)
            | Action::PutDown(_) => &[RightArm],
            _ => &[],
        }
    }

    /// The same gesture with another side.
    pub fn with_side(self, side: Side) -> Action {
        match self {
            Action::Wave(_) | Action::Goodbye => Action::Wave(side),
            Action::Raise(_) => Action::Raise(side),
            other => other,
        }
    }

    /// The action as a caption of the training data ("a person waves the left hand").
    pub fn caption(self) -> String {
        format!("a person {}", self.verb_phrase())
    }

    /// Third-person verb phrase ("waves the left hand").
    pub fn verb_phrase(self) -> String {
        match self {
            Action::Walk(Direction::Forward) => "walks forward".into(),
            Action::Walk(Direction::Backward) => "walks backward".into(),
            Action::Walk(Direction::Left) => "walks to the left".into(),
            Action::Walk(Direction::Right) => "walks to the right".into(),
            // A participle, not "and turns": a planner reading this text again keeps the
            // walk and the turn as one movement, as the training clips are.
            Action::Walk(Direction::TurnLeft) => "walks forward, turning to the left".into(),
            Action::Walk(Direction::TurnRight) => "walks forward, turning to the right".into(),
            Action::Run => "runs forward".into(),
            Action::Dash => "dashes forward at full speed".into(),
            Action::Bow => "bows".into(),
            Action::Kick => "kicks forward with a leg".into(),
            Action::Punch => "throws punches".into(),
            Action::PunchWith(side) => format!("throws a {} punch", side.one()),
            Action::Slash => "slashes as if with a sword".into(),
            Action::Dance => "dances".into(),
            Action::Beckon => "beckons someone to come".into(),
            Action::Guide => "shows the way with a sweep of the arm".into(),
            Action::Wave(side) => format!("waves {}", side.words()),
            Action::Goodbye => "waves goodbye".into(),
            Action::Raise(side) => format!("raises {}", side.words()),
            // Dataset v2: one wording of each label's training captions, chosen so that this
            // planner reads it back as the same action.
            Action::Squat => "does a squat".into(),
            Action::Jump => "jumps up".into(),
            Action::JumpForward => "jumps forward with both feet".into(),
            Action::LieDown => "lies down on the floor".into(),
            Action::FrontKick(side) => format!("kicks with the {} leg", side.one()),
            Action::KickBall(side) => format!("kicks a ball with the {} foot", side.one()),
            Action::Throw => "throws a ball".into(),
            Action::ReachUp(side) => format!("reaches up high with the {} hand", side.one()),
            Action::PutDown(side) => format!(
                "places an object on the ground with the {} hand",
                side.one()
            ),
            Action::Sneak => "sneaks forward".into(),
            Action::ArmCircles => "circles both arms backward".into(),
            Action::ElbowToKnee => "touches each elbow to the opposite knee".into(),
            Action::Basketball => "plays basketball".into(),
            Action::RefereeSignals => "makes referee signals with the arms".into(),
            Action::DirectTraffic => "directs traffic with arm signals".into(),
            Action::WashWindow => "washes a window".into(),
            Action::JogCircle(side) => format!("jogs in a circle to the {}", side.one()),
        }
    }

    /// The gesture as a participle, to join it to a base motion ("waving the left hand").
    pub fn participle(self) -> String {
        match self {
            Action::Wave(side) => format!("waving {}", side.words()),
            Action::Raise(side) => format!("with {} raised", side.words()),
            Action::Goodbye => "waving goodbye".into(),
            Action::Beckon => "gesturing to come".into(),
            Action::Guide => "pointing the way".into(),
            other => other.verb_phrase(),
        }
    }

    /// A usual length in seconds for the action, from the lengths of its training clips.
    /// (Segments are at least 2 s long; shorter lengths are lengthened to that.)
    pub fn seconds(self) -> f64 {
        match self {
            Action::Walk(Direction::TurnLeft | Direction::TurnRight) => 5.0,
            Action::Walk(_) => 4.0,
            Action::Run => 3.5,
            Action::Dash => 3.0,
            Action::Dance => 6.0,
            Action::Kick | Action::Punch | Action::PunchWith(_) => 2.5,
            // Dataset v2 (`data/coma/dataset.json`): the median length of the label's items
            // that are whole clips (not windows of a longer one), frames at 20 fps.
            Action::Squat => 1.5,
            Action::Jump => 2.9,
            Action::JumpForward => 2.2,
            Action::LieDown => 5.65,
            Action::FrontKick(_) => 1.8,
            Action::KickBall(_) => 4.8,
            Action::Throw => 3.0,
            Action::ReachUp(_) => 2.05,
            Action::PutDown(_) => 3.0,
            Action::Sneak => 1.9,
            Action::ArmCircles => 1.5,
            Action::ElbowToKnee => 1.4,
            Action::Basketball => 3.8,
            // Every item of these is a 9.8 s window of a longer take (as the Bandai dances
            // are): a few signals or wipes, like the dance's 6 s, rather than the whole limit.
            Action::RefereeSignals | Action::DirectTraffic | Action::WashWindow => 6.0,
            // Items of 1.6–2.5 s (median 2.0) are pieces of a circle; with the circle as the
            // segment's path its length comes from the path instead.
            Action::JogCircle(_) => 2.0,
            _ => 3.0,
        }
    }
}

/// The hand a punch is thrown with: "a left punch", "punches with the right fist"; `None`
/// for both or none.
fn punch_side(next: &[&str], prev: &[&str]) -> Option<Side> {
    let side = |w: &str| match w {
        "left" => Some(Side::Left),
        "right" => Some(Side::Right),
        _ => None,
    };
    if let Some(s) = prev.first().and_then(|w| side(w)) {
        return Some(s);
    }
    // "punches quickly with the right fist": a manner word says how, not with what.
    let near: Vec<&str> = next
        .iter()
        .filter(|w| !w.ends_with("ly"))
        .take(4)
        .copied()
        .collect();
    let hand = near.iter().any(|w| matches!(*w, "hand" | "fist" | "arm"));
    let sides: Vec<Side> = near.iter().filter_map(|w| side(w)).collect();
    match sides.as_slice() {
        [one] if hand => Some(*one),
        _ => None,
    }
}

/// What a word starts, when it names a movement. `next` holds the words that follow (for
/// phrases such as "turn left").
pub fn action_word(word: &str, next: &[&str], prev: &[&str]) -> Option<Action> {
    let near = |w: &[&str], targets: &[&str]| w.iter().take(3).any(|x| targets.contains(x));
    Some(match word {
        "walk" | "walks" | "walking" | "walked" | "stroll" | "strolls" | "strolling" | "march"
        | "marches" | "marching" | "shuffle" | "shuffles" | "shuffling" | "wander" | "wanders"
        | "wandering" | "pace" | "paces" | "pacing" | "steps" | "stepping" | "sidestep"
        | "sidesteps" | "sidestepping" => Action::Walk(Direction::Forward),
        // "turns in a circle to the left" walks a circle, as "walks in a circle" does.
        "turn" | "turns" | "turning" if near(next, &["circle"]) => Action::Walk(Direction::Forward),
        // "walks forward, turning left" walks; "turns to the left" on its own is the key-pose
        // library's turn on the spot.
        "turning" => {
            if near(next, &["left"]) || prev.last() == Some(&"left") {
                Action::Walk(Direction::TurnLeft)
            } else if near(next, &["right", "around"]) || prev.last() == Some(&"right") {
                Action::Walk(Direction::TurnRight)
            } else {
                return None;
            }
        }
        "run" | "runs" | "running" | "ran" | "jog" | "jogs" | "jogging" | "jogged" | "hurry"
        | "hurries" | "hurrying" | "hurried" | "rush" | "rushes" | "rushing" | "rushed" => {
            Action::Run
        }
        "sprint" | "sprints" | "sprinting" | "dash" | "dashes" | "dashing" | "races" => {
            Action::Dash
        }
        "bow" | "bows" | "bowing" | "bowed" => Action::Bow,
        "kick" | "kicks" | "kicking" | "kicked" => Action::Kick,
        "hook" | "hooks" if prev.first().is_some_and(|w| matches!(*w, "left" | "right")) => {
            punch_side(next, prev).map_or(Action::Punch, Action::PunchWith)
        }
        "punch" | "punches" | "punching" | "punched" | "boxes" | "boxing" | "jab" | "jabs"
        | "uppercut" | "uppercuts" => match punch_side(next, prev) {
            Some(side) => Action::PunchWith(side),
            None => Action::Punch,
        },
        "slash" | "slashes" | "slashing" | "slashed" | "sword" => Action::Slash,
        "dance" | "dances" | "dancing" | "danced" => Action::Dance,
        "beckon" | "beckons" | "beckoning" | "calls" => Action::Beckon,
        "point" | "points" | "pointing" | "guide" | "guides" | "guiding" | "sweep" => Action::Guide,
        "goodbye" | "bye" | "farewell" => Action::Goodbye,
        "wave" | "waves" | "waving" | "waved" | "greet" | "greets" | "greeting" => {
            Action::Wave(Side::Right)
        }
        // "with arms raised", "his right hand lifted": where the arm is, not a raise (the
        // limb's place holds it over the movement).
        "raised" | "lifted"
            if prev
                .first()
                .is_some_and(|w| matches!(*w, "arm" | "arms" | "hand" | "hands")) =>
        {
            return None
        }
        // "lifts the right knee" raises a leg, which no gesture of the arms makes.
        "raise" | "raises" | "raising" | "raised" | "lift" | "lifts" | "lifting" | "lifted"
            if names_leg_first(next) =>
        {
            return None
        }
        "raise" | "raises" | "raising" | "raised" | "lift" | "lifts" | "lifting" | "lifted"
        | "salute" | "salutes" | "saluting" | "hail" | "hails" | "cheer" | "cheers"
        | "cheering" | "celebrates" | "celebrating" | "celebration" => Action::Raise(Side::Right),
        // "hands up", "arm in the air": a raise with no verb.
        "up" | "air" if near(prev, &["hand", "hands", "arm", "arms"]) => Action::Raise(Side::Right),
        _ => return None,
    })
}

/// Whether the words after a verb name a leg before they name an arm ("the right knee up
/// high"), within the verb's object.
fn names_leg_first(next: &[&str]) -> bool {
    for w in next.iter().take(4) {
        match *w {
            "arm" | "arms" | "hand" | "hands" | "fist" | "fists" | "elbow" | "elbows" => {
                return false
            }
            "leg" | "legs" | "knee" | "knees" | "foot" | "feet" | "heel" | "heels" => return true,
            "," | "and" | "then" | "while" | "with" => return false,
            _ => {}
        }
    }
    false
}

/// The actions of dataset v2 a loaded model makes, read from its vocabulary: an action is
/// known when the vocabulary lists its label and every word of its caption phrase, so the
/// planner plans for a model trained without them (the v1 vocabulary, or none) as before.
#[derive(Clone, Copy, Debug, Default)]
pub struct Repertoire<'a> {
    vocabulary: Option<&'a Vocabulary>,
}

impl<'a> Repertoire<'a> {
    /// The repertoire of the model with `vocabulary`; with none, only the Bandai Namco
    /// actions.
    pub fn new(vocabulary: Option<&'a Vocabulary>) -> Repertoire<'a> {
        Repertoire { vocabulary }
    }

    /// Whether the model makes `action` from its caption: always for the Bandai Namco
    /// actions; for an action of dataset v2 when the vocabulary has its label and words.
    pub fn knows(&self, action: Action) -> bool {
        let Some(label) = action.label() else {
            return true;
        };
        let Some(vocabulary) = self.vocabulary else {
            return false;
        };
        vocabulary.actions.contains_key(&label)
            && action
                .verb_phrase()
                .split(|c: char| !c.is_alphanumeric() && c != '-')
                .filter(|w| !w.is_empty())
                .all(|w| vocabulary.words.iter().any(|v| v == w))
    }

    /// Whether the model knows any action of dataset v2.
    pub fn knows_any(&self) -> bool {
        DATASET_ACTIONS.iter().any(|a| self.knows(*a))
    }
}

/// Words that end what a word's neighbours can say about it ("kicks, then raises the left
/// hand": the side is the hand's, not the kick's).
fn is_boundary(word: &str) -> bool {
    matches!(
        word,
        "then" | "and" | "while" | "whilst" | "," | "." | "before" | "after"
    )
}

/// Body parts, as the object of a verb that otherwise puts a thing somewhere ("puts his
/// hands on the ground" is a pose, not putting something down).
const BODY_WORDS: &[&str] = &[
    "hand",
    "hands",
    "arm",
    "arms",
    "foot",
    "feet",
    "leg",
    "legs",
    "knee",
    "knees",
    "head",
    "palm",
    "palms",
    "fist",
    "fists",
    "body",
    "himself",
    "herself",
    "themselves",
    "elbow",
    "elbows",
];

/// The side a one-limb action at `i` names ("kicks with the left foot", "with his right
/// hand, reaches up", "reaches up and grabs something with the left hand"), else the right:
/// most people kick and reach with the right, and the data has both sides alike (every take
/// is also mirrored).
fn limb_side(words: &[&str], i: usize) -> Side {
    // "and" goes on to the same movement unless a verb of another one follows ("kicks and
    // raises the left hand").
    let goes_on = |k: usize| {
        words[k] == "and"
            && words
                .get(k + 1)
                .is_some_and(|n| !is_finite_verb(n) && !is_dataset_verb(n))
    };
    let after = (i + 1..words.len())
        .take_while(|k| !is_boundary(words[*k]) || goes_on(*k))
        .map(|k| &words[k])
        .take(10);
    let before = words[..i]
        .iter()
        .rev()
        .take_while(|w| !is_boundary(w))
        .take(4);
    for w in after.chain(before) {
        match *w {
            "left" => return Side::Left,
            "right" => return Side::Right,
            _ => {}
        }
    }
    Side::Right
}

/// The action of dataset v2 that word `i` of a clause names, read with the words around it:
/// "squats", "jumps forward", "lies down on the floor", "kicks a ball with the left foot",
/// "throws a ball", "reaches up with the left hand", "puts the box down", "tiptoes",
/// "walks stealthily", "does arm circles", "plays basketball", "directs traffic", "washes a
/// window". `None` where the word names none of them, or a variant the data does not hold
/// (jumping backward or sideways, lying on the stomach, reaching up with both hands), which
/// the posture library makes instead. Whether the model knows the action is not checked here
/// ([`Repertoire::knows`]).
pub fn dataset_action(words: &[&str], i: usize) -> Option<Action> {
    let w = words[i];
    let has = |set: &[&str]| words.iter().any(|x| set.contains(x));
    let after = |n: usize| -> Vec<&str> {
        words[i + 1..]
            .iter()
            .take_while(|x| !is_boundary(x))
            .take(n)
            .copied()
            .collect()
    };
    let after_has = |n: usize, set: &[&str]| after(n).iter().any(|x| set.contains(x));
    let prev = i.checked_sub(1).map(|k| words[k]);
    let side = || limb_side(words, i);
    const KICK: &[&str] = &["kick", "kicks", "kicking", "kicked"];
    const SOCCER: &[&str] = &["ball", "soccer", "football", "goal", "penalty"];
    const THROW: &[&str] = &[
        "throw", "throws", "throwing", "threw", "toss", "tosses", "tossing", "tossed", "pitches",
        "pitching", "pitched",
    ];
    Some(match w {
        "squat" | "squats" | "squatting" | "squatted" => Action::Squat,
        "jump" | "jumps" | "jumping" | "jumped" | "hop" | "hops" | "hopping" | "hopped"
        | "leap" | "leaps" | "leaping" | "leapt" | "leaped" => {
            const ELSEWHERE: &[&str] = &[
                "backward",
                "backwards",
                "back",
                "sideways",
                "aside",
                "left",
                "right",
                "around",
            ];
            if after_has(4, ELSEWHERE) {
                return None;
            }
            let forward = after_has(4, &["forward", "forwards", "ahead", "over", "across"]);
            if forward || matches!(prev, Some("long" | "broad")) {
                Action::JumpForward
            } else {
                Action::Jump
            }
        }
        "lie" | "lies" | "lying" => lies_down(&after(6))?,
        // "lays down" is lying down; "lays the baby down" is putting something down.
        "lay" | "lays" | "laying" | "laid" => {
            let next = after(6);
            if matches!(next.first(), Some(&("down" | "on" | "onto" | "flat"))) {
                lies_down(&next)?
            } else {
                puts_down(&after(8), side())?
            }
        }
        "put" | "puts" | "putting" | "place" | "places" | "placing" | "placed" | "set" | "sets"
        | "setting" => puts_down(&after(8), side())?,
        _ if KICK.contains(&w) => {
            if has(SOCCER) {
                Action::KickBall(side())
            } else {
                Action::FrontKick(side())
            }
        }
        "soccer" | "football" if !has(KICK) && !has(THROW) => Action::KickBall(side()),
        // Dribbling is basketball's unless the clause says soccer.
        "dribble" | "dribbles" | "dribbling" | "dribbled" => {
            if has(&["soccer", "football"]) {
                Action::KickBall(side())
            } else {
                Action::Basketball
            }
        }
        _ if THROW.contains(&w) => {
            // "throws punches", "throws a kick", "throws the arms up": not a throw of a ball.
            const NOT_A_BALL: &[&str] = &[
                "punch", "punches", "kick", "kicks", "jab", "jabs", "hook", "hooks", "uppercut",
                "fit", "tantrum", "up",
            ];
            let next = after(3);
            if next
                .iter()
                .any(|x| NOT_A_BALL.contains(x) || BODY_WORDS.contains(x))
            {
                return None;
            }
            Action::Throw
        }
        "reach" | "reaches" | "reaching" | "reached" => {
            let high = [
                "up", "upward", "upwards", "high", "higher", "overhead", "shelf",
            ];
            if !after_has(5, &high) || has(&["both", "hands", "arms"]) {
                return None;
            }
            Action::ReachUp(side())
        }
        // "stretches the left arm up": one arm reaching up.
        "stretch" | "stretches" | "stretching" | "stretched" => {
            let next = after(5);
            let one_arm = next.iter().any(|x| matches!(*x, "left" | "right"))
                && next.iter().any(|x| matches!(*x, "arm" | "hand"));
            if !(one_arm && next.iter().any(|x| matches!(*x, "up" | "upward" | "high"))) {
                return None;
            }
            Action::ReachUp(side())
        }
        "sneak" | "sneaks" | "sneaking" | "sneaked" | "snuck" | "tiptoe" | "tiptoes"
        | "tiptoeing" | "tiptoed" | "creep" | "creeps" | "creeping" | "crept" | "prowl"
        | "prowls" | "prowling" => Action::Sneak,
        _ if has(&["stealthily", "quietly", "silently", "sneakily"])
            && action_word(w, &[], &[]) == Some(Action::Walk(Direction::Forward)) =>
        {
            Action::Sneak
        }
        "circle" | "circles"
            if matches!(prev, Some("arm" | "arms"))
                || has(&["arm", "arms"])
                    && (matches!(
                        prev,
                        Some("backward" | "backwards" | "forward" | "forwards" | "big" | "small")
                    ) || has(&["swing", "swings", "swinging", "move", "moves", "moving"])) =>
        {
            Action::ArmCircles
        }
        "circles" | "circling" | "rotate" | "rotates" | "rotating" | "windmill" | "windmills"
        | "windmilling"
            if !matches!(prev, Some("in" | "a"))
                && after_has(3, &["arm", "arms", "shoulder", "shoulders"]) =>
        {
            Action::ArmCircles
        }
        "elbow" | "elbows" if after_has(5, &["knee", "knees"]) => Action::ElbowToKnee,
        "basketball" | "hoops" | "basket" | "baskets"
            if !has(&["referee", "referees"]) && !has(THROW) =>
        {
            if matches!(w, "basket" | "baskets") && !has(&["shoot", "shoots", "shooting"]) {
                return None;
            }
            Action::Basketball
        }
        "referee" | "referees" | "umpire" | "umpires" => {
            const SIGNALS: &[&str] = &[
                "signal",
                "signals",
                "signaling",
                "signalling",
                "signs",
                "gesture",
                "gestures",
                "gesturing",
                "whistle",
                "whistles",
                "foul",
            ];
            let like = i >= 2 && matches!(words[i - 2], "like" | "as");
            if !(like || has(SIGNALS)) {
                return None;
            }
            Action::RefereeSignals
        }
        "traffic"
            if has(&[
                "direct",
                "directs",
                "directing",
                "directed",
                "signal",
                "signals",
                "signaling",
                "signalling",
                "control",
                "controls",
                "controlling",
                "police",
                "policeman",
                "policewoman",
                "officer",
                "cop",
                "warden",
            ]) =>
        {
            Action::DirectTraffic
        }
        "window" | "windows" | "windshield" | "windscreen" | "mirror" | "glass"
            if has(&[
                "wash",
                "washes",
                "washing",
                "washed",
                "wipe",
                "wipes",
                "wiping",
                "wiped",
                "clean",
                "cleans",
                "cleaning",
                "cleaned",
                "polish",
                "polishes",
                "polishing",
                "scrub",
                "scrubs",
                "scrubbing",
            ]) =>
        {
            Action::WashWindow
        }
        _ => return None,
    })
}

/// After a word of lying: lying down when the words go down or to the floor ("lies down",
/// "lies on the floor", "lays down on his back"); `None` for a lying pose the data does not
/// get into (on the stomach or side, face down) or one only held ("lies still").
fn lies_down(next: &[&str]) -> Option<Action> {
    const NOT_IN_DATA: &[&str] = &[
        "stomach",
        "belly",
        "front",
        "side",
        "face",
        "still",
        "motionless",
    ];
    if next.iter().any(|x| NOT_IN_DATA.contains(x)) {
        return None;
    }
    let down = next.contains(&"down");
    let floor = next
        .iter()
        .take(4)
        .any(|x| matches!(*x, "floor" | "ground"));
    (down || floor).then_some(Action::LieDown)
}

/// After a verb of putting: putting something down with one hand when the words go down or
/// to the floor ("puts the box down", "places a cup on the ground"); `None` when what is put
/// is a body part ("puts his hands on the ground") or it goes elsewhere (on a table).
fn puts_down(next: &[&str], side: Side) -> Option<Action> {
    let to = next
        .iter()
        .position(|x| matches!(*x, "down" | "floor" | "ground"))?;
    if next[..to].iter().any(|x| BODY_WORDS.contains(x)) {
        return None;
    }
    Some(Action::PutDown(side))
}

/// Verbs that start a movement of dataset v2 and nothing the rest of the lexicon knows
/// ("squats, throws a ball": the comma starts a new movement). Read only for a model that
/// knows those actions.
pub fn is_dataset_verb(word: &str) -> bool {
    matches!(
        word,
        "throw"
            | "throws"
            | "toss"
            | "tosses"
            | "sneak"
            | "sneaks"
            | "tiptoe"
            | "tiptoes"
            | "place"
            | "places"
            | "play"
            | "plays"
            | "dribble"
            | "dribbles"
            | "wash"
            | "washes"
            | "wipe"
            | "wipes"
            | "clean"
            | "cleans"
            | "direct"
            | "directs"
            | "signal"
            | "signals"
            | "circles"
            | "rotates"
    )
}

/// A count written just before a movement's noun at `at` ("three squats", "3 kicks", "a
/// couple of jumps").
pub fn count_before(words: &[&str], at: usize) -> Option<usize> {
    let before = &words[..at];
    if before.ends_with(&["a", "couple", "of"]) || before.ends_with(&["a", "pair", "of"]) {
        return Some(2);
    }
    if before.ends_with(&["a", "few"]) {
        return Some(3);
    }
    let n = number(before.last()?)?;
    (n >= 1.0).then(|| n.round().min(100.0) as usize)
}

/// A count between a verb at `at` and its plural object ("throws **two** punches", "does
/// **three** kicks"); not a measure ("walks two metres", "takes two steps").
pub fn count_after(words: &[&str], at: usize) -> Option<usize> {
    let n = number(words.get(at + 1)?)?;
    let noun = words.get(at + 2)?;
    let measure = matches!(
        *noun,
        "times" | "metres" | "meters" | "feet" | "yards" | "steps" | "seconds" | "secs" | "minutes"
    );
    (n >= 2.0 && noun.ends_with('s') && !measure).then(|| n.round().min(100.0) as usize)
}

/// Gestures that name no side but mean both arms.
pub fn both_by_default(word: &str) -> bool {
    matches!(
        word,
        "cheer" | "cheers" | "cheering" | "celebrates" | "celebrating" | "celebration"
    )
}

/// Words that start a verb phrase: a clause that begins with one of them (after its subject)
/// is a new movement. Participles ("waving") are not here: they join the clause before.
pub fn is_finite_verb(word: &str) -> bool {
    const OTHER: &[&str] = &[
        "stop",
        "stops",
        "stand",
        "stands",
        "pause",
        "pauses",
        "wait",
        "waits",
        "slow",
        "slows",
        "perform",
        "performs",
        "do",
        "does",
        "make",
        "makes",
        "take",
        "takes",
        "go",
        "goes",
        "head",
        "heads",
        "move",
        "moves",
        "come",
        "comes",
        "greet",
        "greets",
        "jump",
        "jumps",
        "kneel",
        "kneels",
        "spin",
        "spins",
        "turn",
        "turns",
        "sit",
        "sits",
        "rest",
        "rests",
        "finish",
        "finishes",
        "end",
        "ends",
        "leave",
        "leaves",
        "exit",
        "exits",
        "start",
        "starts",
        "begin",
        "begins",
        "keep",
        "keeps",
        "continue",
        "continues",
        "transition",
        "transitions",
        "switch",
        "switches",
        "change",
        "changes",
    ];
    if OTHER.contains(&word) {
        return true;
    }
    !word.ends_with("ing")
        && !word.ends_with("ed")
        && action_word(word, &["left"], &[]).is_some()
        && !matches!(
            word,
            "sword" | "sweep" | "goodbye" | "bye" | "farewell" | "celebration" | "up" | "air"
        )
}

/// A clause without the words that name the person at its start ("a dancer spreads …" is
/// "spreads …"): segment texts are about "a person", and "dancer" would make any clause a
/// dance to the sentence encoder.
pub fn without_subject<'a>(words: &[&'a str]) -> Vec<&'a str> {
    words
        .iter()
        .copied()
        .skip_while(|w| is_subject_word(w) || is_subject_noun(w))
        .collect()
}

/// Nouns prompts use for the person ("the girl", "an athlete"): dropped from a segment's text.
pub fn is_subject_noun(word: &str) -> bool {
    matches!(
        word,
        "man"
            | "woman"
            | "girl"
            | "boy"
            | "child"
            | "kid"
            | "person"
            | "someone"
            | "athlete"
            | "dancer"
            | "player"
            | "student"
            | "soldier"
            | "monk"
            | "runner"
            | "referee"
            | "gymnast"
            | "hiker"
            | "fan"
            | "winner"
            | "singer"
            | "model"
            | "climber"
            | "bodybuilder"
            | "cheerleader"
            | "goalkeeper"
            | "people"
            | "guy"
            | "lady"
            | "his"
            | "her"
            | "old"
            | "young"
    )
}

/// Words a clause may start with before its verb ("the speaker", "they", "he then").
pub fn is_subject_word(word: &str) -> bool {
    matches!(
        word,
        "he" | "she"
            | "they"
            | "it"
            | "someone"
            | "somebody"
            | "person"
            | "the"
            | "a"
            | "an"
            | "this"
            | "that"
            | "then"
            | "also"
            | "finally"
            | "slowly"
            | "quickly"
            | "just"
    )
}

/// A style the training data knows, as the phrase its captions use.
pub fn style_word(word: &str) -> Option<&'static str> {
    Some(match word {
        "angry" | "angrily" | "furious" | "furiously" | "mad" | "annoyed" => "angrily",
        "happy" | "happily" | "cheerful" | "cheerfully" | "joyful" | "joyfully" | "laughing"
        | "excited" | "excitedly" => "happily",
        "sad" | "sadly" | "depressed" | "gloomy" | "upset" | "unhappy" => "sadly",
        "tired" | "tiredly" | "exhausted" | "weary" | "wearily" | "sleepy" => "tiredly",
        "proud" | "proudly" | "confident" | "confidently" => "proudly",
        "timid" | "timidly" | "shy" | "shyly" | "nervous" | "nervously" | "unsure" => "timidly",
        "old" | "elderly" | "aged" => "like an elderly person",
        "energetic" | "energetically" | "active" | "actively" | "lively" | "vigorous"
        | "vigorously" => "energetically",
        "graceful" | "gracefully" | "elegant" | "elegantly" | "feminine" => "gracefully",
        "masculine" | "manly" => "with a masculine manner",
        "child" | "childish" | "childishly" | "childlike" | "kid" => "in a childlike way",
        "giant" => "like a giant",
        "thug" | "swaggering" => "like a thug",
        _ => return None,
    })
}

/// Words that change a segment's length: a factor on its usual duration.
pub fn tempo_word(word: &str) -> Option<f64> {
    match word {
        "slowly" | "slow" | "leisurely" => Some(1.25),
        "quickly" | "quick" | "briefly" | "brief" | "fast" => Some(0.75),
        _ => None,
    }
}

/// A count of repetitions ("twice", "three times").
pub fn repetitions(words: &[&str]) -> usize {
    for (i, w) in words.iter().enumerate() {
        let times = words.get(i + 1) == Some(&"times");
        match *w {
            "twice" => return 2,
            "thrice" => return 3,
            "two" if times => return 2,
            "three" if times => return 3,
            "four" if times => return 4,
            "2" if times => return 2,
            "3" if times => return 3,
            "4" if times => return 4,
            _ => {}
        }
    }
    1
}

/// A number written as digits or as a word from one to ten.
pub fn number(word: &str) -> Option<f64> {
    const WORDS: [&str; 10] = [
        "one", "two", "three", "four", "five", "six", "seven", "eight", "nine", "ten",
    ];
    if let Some(i) = WORDS.iter().position(|w| *w == word) {
        return Some((i + 1) as f64);
    }
    word.parse::<f64>().ok().filter(|x| x.is_finite())
}
