//! The words the built-in planner understands, and the caption phrases it answers with.
//!
//! Every phrase it writes uses only words of the training captions (checked by a test
//! against `static/models/vocabulary.json`), so the motion model reads text it has seen.

/// Which arm or arms a gesture uses.
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

/// A movement the training data holds (the Bandai Namco action labels).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Action {
    Walk(Direction),
    Run,
    Dash,
    Bow,
    Kick,
    Punch,
    Slash,
    Dance,
    Beckon,
    Guide,
    Wave(Side),
    Goodbye,
    Raise(Side),
}

impl Action {
    /// Moves the whole body through space.
    pub fn is_locomotion(self) -> bool {
        matches!(self, Action::Walk(_) | Action::Run | Action::Dash)
    }

    /// Done with the arms alone, so it can ride on another motion as a part edit.
    pub fn is_gesture(self) -> bool {
        matches!(
            self,
            Action::Wave(_) | Action::Raise(_) | Action::Goodbye | Action::Beckon | Action::Guide
        )
    }

    /// The arms a gesture uses (none for whole-body actions).
    pub fn arms(self) -> &'static [crate::skeleton::BodyPart] {
        use crate::skeleton::BodyPart::{LeftArm, RightArm};
        match self {
            Action::Wave(Side::Left) | Action::Raise(Side::Left) => &[LeftArm],
            Action::Wave(Side::Both) | Action::Raise(Side::Both) => &[LeftArm, RightArm],
            Action::Wave(_)
            | Action::Raise(_)
            | Action::Goodbye
            | Action::Beckon
            | Action::Guide => &[RightArm],
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
            Action::Slash => "slashes as if with a sword".into(),
            Action::Dance => "dances".into(),
            Action::Beckon => "beckons someone to come".into(),
            Action::Guide => "shows the way with a sweep of the arm".into(),
            Action::Wave(side) => format!("waves {}", side.words()),
            Action::Goodbye => "waves goodbye".into(),
            Action::Raise(side) => format!("raises {}", side.words()),
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
    pub fn seconds(self) -> f64 {
        match self {
            Action::Walk(Direction::TurnLeft | Direction::TurnRight) => 5.0,
            Action::Walk(_) => 4.0,
            Action::Run => 3.5,
            Action::Dash => 3.0,
            Action::Dance => 6.0,
            Action::Kick | Action::Punch => 2.5,
            _ => 3.0,
        }
    }
}

/// What a word starts, when it names a movement. `next` holds the words that follow (for
/// phrases such as "turn left").
pub fn action_word(word: &str, next: &[&str], prev: &[&str]) -> Option<Action> {
    let near = |w: &[&str], targets: &[&str]| w.iter().take(3).any(|x| targets.contains(x));
    Some(match word {
        "walk" | "walks" | "walking" | "walked" | "stroll" | "strolls" | "strolling" | "march"
        | "marches" | "marching" | "shuffle" | "shuffles" | "shuffling" | "wander" | "wanders"
        | "wandering" | "pace" | "paces" | "pacing" | "steps" | "stepping" => {
            Action::Walk(Direction::Forward)
        }
        "turn" | "turns" | "turning" | "turned" => {
            if near(next, &["left"]) || prev.last() == Some(&"left") {
                Action::Walk(Direction::TurnLeft)
            } else if near(next, &["right", "around"]) || prev.last() == Some(&"right") {
                Action::Walk(Direction::TurnRight)
            } else {
                return None;
            }
        }
        "run" | "runs" | "running" | "ran" | "jog" | "jogs" | "jogging" | "jogged" => Action::Run,
        "sprint" | "sprints" | "sprinting" | "dash" | "dashes" | "dashing" | "races" => {
            Action::Dash
        }
        "bow" | "bows" | "bowing" | "bowed" => Action::Bow,
        "kick" | "kicks" | "kicking" | "kicked" => Action::Kick,
        "punch" | "punches" | "punching" | "punched" | "boxes" | "boxing" => Action::Punch,
        "slash" | "slashes" | "slashing" | "slashed" | "sword" => Action::Slash,
        "dance" | "dances" | "dancing" | "danced" => Action::Dance,
        "beckon" | "beckons" | "beckoning" | "calls" => Action::Beckon,
        "point" | "points" | "pointing" | "guide" | "guides" | "guiding" | "sweep" => Action::Guide,
        "goodbye" | "bye" | "farewell" => Action::Goodbye,
        "wave" | "waves" | "waving" | "waved" | "greet" | "greets" | "greeting" => {
            Action::Wave(Side::Right)
        }
        "raise" | "raises" | "raising" | "raised" | "lift" | "lifts" | "lifting" | "lifted"
        | "salute" | "salutes" | "saluting" | "hail" | "hails" | "cheer" | "cheers"
        | "cheering" | "celebrates" | "celebrating" | "celebration" => Action::Raise(Side::Right),
        // "hands up", "arm in the air": a raise with no verb.
        "up" | "air" if near(prev, &["hand", "hands", "arm", "arms"]) => Action::Raise(Side::Right),
        _ => return None,
    })
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
        "sit",
        "sits",
        "rest",
        "rests",
        "finish",
        "finishes",
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
