//! Global captions of a clip from its content and style labels, worded several ways so the
//! text encoder sees varied language for the same motion ("a person walks forward tiredly",
//! "someone walks ahead, looking tired").

/// The label a content becomes when the motion is mirrored left/right.
pub fn mirror_content(content: &str) -> String {
    if content.contains("left") {
        content.replace("left", "right")
    } else {
        content.replace("right", "left")
    }
}

/// Ways to say what the motion is, third person present, without a subject, for labels
/// worded as a whole (sided labels of the sources that name the side themselves included).
fn fixed_phrases(content: &str) -> &'static [&'static str] {
    match content {
        "walk" => &[
            "walks forward",
            "walks straight ahead",
            "takes a walk forward",
            "walks ahead",
        ],
        "run" => &["runs forward", "jogs forward", "runs straight ahead"],
        "dash" => &[
            "sprints forward",
            "dashes forward at full speed",
            "runs fast straight ahead",
        ],
        "walk-back" => &[
            "walks backward",
            "steps backwards",
            "walks backwards slowly",
        ],
        "walk-left" => &[
            "walks to the left",
            "walks towards the left",
            "moves to the left while walking",
        ],
        "walk-right" => &[
            "walks to the right",
            "walks towards the right",
            "moves to the right while walking",
        ],
        "walk-turn-left" => &[
            "walks forward and turns left",
            "walks and makes a left turn",
            "walks, turning to the left",
        ],
        "walk-turn-right" => &[
            "walks forward and turns right",
            "walks and makes a right turn",
            "walks, turning to the right",
        ],
        "bow" => &[
            "bows",
            "bows politely",
            "bends forward at the waist in a bow",
        ],
        "bye" => &[
            "waves goodbye",
            "waves a hand to say goodbye",
            "says goodbye with a wave",
        ],
        "byebye" => &[
            "waves goodbye energetically",
            "waves goodbye with big arm movements",
            "says bye-bye with a big wave",
        ],
        "guide" => &[
            "gestures with an arm to guide someone",
            "shows the way with a sweep of the arm",
            "points the way with an open hand",
        ],
        "respond" => &[
            "responds to someone with a gesture",
            "answers with a gesture",
            "reacts to someone with a gesture",
        ],
        "call" => &[
            "calls someone over with a gesture",
            "beckons someone to come",
            "calls out to someone, gesturing",
        ],
        "punch" => &["punches", "throws punches", "punches forward"],
        "kick" => &["kicks", "kicks forward with a leg", "throws a kick"],
        "slash" => &[
            "slashes as if with a sword",
            "swings an arm in a slashing motion",
            "makes a sword slash",
        ],
        "dance-long" | "dance-short" => &["dances", "dances energetically", "performs a dance"],
        "wave-both-hands" => &[
            "waves both hands",
            "waves with both hands raised",
            "waves both arms in greeting",
        ],
        "wave-left-hand" => &[
            "waves the left hand",
            "waves with the left hand",
            "raises the left hand and waves",
        ],
        "wave-right-hand" => &[
            "waves the right hand",
            "waves with the right hand",
            "raises the right hand and waves",
        ],
        "raise-up-both-hands" => &[
            "raises both hands",
            "lifts both arms up",
            "raises both hands above the head",
        ],
        "raise-up-left-hand" => &[
            "raises the left hand",
            "lifts the left arm up",
            "raises the left hand up high",
        ],
        "raise-up-right-hand" => &[
            "raises the right hand",
            "lifts the right arm up",
            "raises the right hand up high",
        ],
        "squat" => &[
            "does a squat",
            "squats down and stands back up",
            "bends the knees into a deep squat and rises again",
            "crouches down into a squat, then stands up",
        ],
        "jump" => &["jumps", "jumps up", "does a jump", "jumps with both feet"],
        "jump-forward" => &[
            "jumps forward with both feet",
            "hops forward on both legs",
            "does a two-footed jump forward",
            "leaps forward with the feet together",
        ],
        "lie-down" => &[
            "lies down on the floor",
            "gets down and lies on the ground",
            "lowers the body to lie flat on the floor",
            "kneels and then lies down on the ground",
        ],
        "elbow-to-knee" => &[
            "touches each elbow to the opposite knee",
            "does an elbow-to-knee exercise",
            "twists to bring the elbows to the opposite knees",
        ],
        "jog-circle-left" => &[
            "jogs in a circle to the left",
            "runs slowly in a counterclockwise circle",
            "jogs around, curving to the left",
        ],
        "jog-circle-right" => &[
            "jogs in a circle to the right",
            "runs slowly in a clockwise circle",
            "jogs around, curving to the right",
        ],
        "arm-circles" => &[
            "circles both arms backward",
            "rotates both arms backwards",
            "swings both arms around in backward circles",
        ],
        "sneak" => &[
            "sneaks forward",
            "tiptoes forward quietly",
            "walks stealthily",
            "creeps forward carefully",
        ],
        "throw" => &[
            "throws a ball",
            "throws a basketball",
            "makes a throwing motion",
        ],
        "basketball" => &[
            "plays basketball",
            "dribbles and shoots a basketball",
            "dribbles a ball and shoots",
        ],
        "referee-signals" => &[
            "makes referee signals with the arms",
            "signals with both arms like a referee",
            "gestures like a basketball referee",
        ],
        "direct-traffic" => &[
            "directs traffic with arm signals",
            "waves the arms to direct traffic",
            "signals to cars with the arms like a traffic officer",
        ],
        "kick-ball" => &[
            "kicks a ball",
            "kicks a soccer ball",
            "plays soccer, kicking the ball",
        ],
        "wash-window" => &[
            "washes a window",
            "wipes a window in circles",
            "cleans a window with one hand",
        ],
        "backflip" => &[
            "does a backflip",
            "flips over backwards",
            "jumps and flips backwards",
        ],
        "cartwheel" => &[
            "does a cartwheel",
            "turns a cartwheel",
            "cartwheels sideways",
        ],
        "crawl" => &[
            "crawls on hands and knees",
            "crawls forward",
            "crawls forward on all fours",
        ],
        "dance" => &["dances", "dances energetically", "performs a dance"],
        "dance-spin" => &[
            "dances and spins around",
            "spins around while dancing",
            "twirls around in a dance",
        ],
        "get-up-face-down" => &[
            "gets up from lying face down",
            "pushes up off the floor and stands up",
            "rises from lying on the stomach",
        ],
        "get-up-face-up" => &[
            "gets up from lying on the back",
            "sits up and stands up from the floor",
            "rises from lying face up",
        ],
        "jog" => &["jogs forward", "jogs", "runs at an easy pace"],
        "start-walking" => &[
            "starts walking from standing",
            "begins to walk forward",
            "stands still, then walks off",
        ],
        "stop-walking" => &[
            "walks and comes to a stop",
            "walks forward and stops",
            "slows down and stops walking",
        ],
        "roll" => &[
            "rolls forward on the ground",
            "does a forward roll",
            "tumbles forward",
        ],
        "sideflip" => &[
            "does a side flip",
            "flips sideways in the air",
            "does an aerial side flip",
        ],
        "spin" => &[
            "spins around",
            "turns around in a full spin",
            "spins in place",
        ],
        "spin-kick" => &[
            "does a spinning kick",
            "spins and kicks",
            "turns around and kicks",
        ],
        "zombie-walk" => &[
            "walks like a zombie",
            "shuffles forward like a zombie with the arms out",
            "staggers forward like a zombie",
        ],
        _ => &[],
    }
}

/// Wordings with a `{side}` slot for actions done with one limb, keyed by the label without
/// its `-left-leg` / `-right-hand` ending.
fn sided_phrases(base: &str) -> &'static [&'static str] {
    match base {
        "kick" => &[
            "kicks with the {side} leg",
            "kicks forward with the {side} foot",
            "does a front kick with the {side} leg",
        ],
        "kick-ball" => &[
            "kicks a ball with the {side} foot",
            "kicks a soccer ball with the {side} leg",
            "plays soccer, kicking with the {side} foot",
        ],
        "spin-kick" => &[
            "does a spinning kick with the {side} leg",
            "spins and kicks with the {side} foot",
        ],
        "punch" => &[
            "punches with the {side} hand",
            "throws a {side} punch",
            "punches forward with the {side} fist",
        ],
        "slash" => &[
            "slashes with the {side} hand as if with a sword",
            "swings the {side} arm in a slashing motion",
        ],
        "throw" => &[
            "throws a ball with the {side} hand",
            "throws a basketball with the {side} hand",
            "makes a throwing motion with the {side} arm",
        ],
        "put-down" => &[
            "bends down and puts something on the floor with the {side} hand",
            "places an object on the ground with the {side} hand",
            "crouches to set something down with the {side} hand",
        ],
        "reach-up" => &[
            "reaches up high with the {side} hand",
            "reaches up and grabs something high with the {side} hand",
            "stretches the {side} arm up to take something from a high shelf",
        ],
        _ => &[],
    }
}

/// Splits `kick-left-leg` into `kick` and `left`; `None` for labels without a side ending.
fn side_ending(content: &str) -> Option<(&str, &'static str)> {
    for (ending, side) in [
        ("-left-leg", "left"),
        ("-right-leg", "right"),
        ("-left-hand", "left"),
        ("-right-hand", "right"),
    ] {
        if let Some(base) = content.strip_suffix(ending) {
            return Some((base, side));
        }
    }
    None
}

/// Ways to say what the motion is, third person present, without a subject; empty for labels
/// we have no wording for.
fn action_phrases(content: &str) -> Vec<String> {
    let fixed = fixed_phrases(content);
    if !fixed.is_empty() {
        return fixed.iter().map(|p| p.to_string()).collect();
    }
    let Some((base, side)) = side_ending(content) else {
        return Vec::new();
    };
    let templates = sided_phrases(base);
    if !templates.is_empty() {
        return templates
            .iter()
            .map(|t| t.replace("{side}", side))
            .collect();
    }
    let limb = if content.ends_with("-leg") {
        "leg"
    } else {
        "hand"
    };
    fixed_phrases(base)
        .iter()
        .map(|p| format!("{p} with the {side} {limb}"))
        .collect()
}

/// A fallback phrase for content labels we have no wording for: the label's words.
fn label_phrase(content: &str) -> String {
    content.replace('-', " ")
}

/// Style wordings: an adverb or manner phrase placed after the action, and an adjective for
/// the subject. `None` for the neutral style.
fn style_words(style: &str) -> Option<(&'static [&'static str], &'static str)> {
    Some(match style {
        "normal" => return None,
        "happy" => (&["happily", "in a happy way", "cheerfully"], "happy"),
        "sad" => (&["sadly", "in a sad way", "looking sad"], "sad"),
        "angry" => (&["angrily", "in an angry way", "looking angry"], "angry"),
        "proud" => (
            &["proudly", "in a proud way", "with a proud posture"],
            "proud",
        ),
        "not-confident" => (
            &["timidly", "without confidence", "in an unsure way"],
            "timid",
        ),
        "masculinity" | "masculine" => (
            &[
                "in a masculine way",
                "with a masculine manner",
                "in a manly style",
            ],
            "masculine",
        ),
        "feminine" => (
            &["in a feminine way", "with a feminine manner", "gracefully"],
            "feminine",
        ),
        "childish" => (
            &["childishly", "like a child", "in a childlike way"],
            "childlike",
        ),
        "old" | "elderly" => (
            &[
                "like an old person",
                "slowly like an elderly person",
                "in an elderly way",
            ],
            "elderly",
        ),
        "tired" | "exhausted" => (
            &["tiredly", "looking exhausted", "in an exhausted way"],
            "tired",
        ),
        "active" => (
            &["energetically", "actively", "in a lively way"],
            "energetic",
        ),
        "musical" => (
            &[
                "rhythmically, like in a musical",
                "in a theatrical, musical way",
                "with musical flair",
            ],
            "theatrical",
        ),
        "giant" => (
            &[
                "heavily like a giant",
                "with big heavy movements",
                "like a giant",
            ],
            "giant",
        ),
        "chimpira" => (
            &[
                "like a thug",
                "in a swaggering thug style",
                "with a tough swagger",
            ],
            "swaggering",
        ),
        "youthful" => (
            &["youthfully", "in a youthful way", "with youthful energy"],
            "young",
        ),
        _ => return None,
    })
}

const SUBJECTS: [&str; 4] = ["a person", "someone", "the person", "a human"];

/// The caption with its subject ("someone", "a human", …, the words [`global_captions`]
/// varies) said as "a person": captions that differ only there describe the same motion.
pub fn with_plain_subject(caption: &str) -> String {
    SUBJECTS
        .iter()
        .find_map(|s| caption.strip_prefix(s)?.strip_prefix(' '))
        .map_or_else(|| caption.to_string(), |rest| format!("a person {rest}"))
}

/// A small deterministic hash so every clip gets its own but reproducible choice of words.
pub fn stable_hash(text: &str) -> u64 {
    text.bytes().fold(0xcbf2_9ce4_8422_2325u64, |h, b| {
        (h ^ b as u64).wrapping_mul(0x100_0000_01b3)
    })
}

/// `count` distinct global captions for a clip, chosen deterministically from `seed`.
pub fn global_captions(content: &str, style: &str, seed: &str, count: usize) -> Vec<String> {
    let mut actions = action_phrases(content);
    if actions.is_empty() {
        actions.push(label_phrase(content));
    }
    let style = style_words(style);
    let mut candidates = Vec::new();
    for (i, action) in actions.iter().enumerate() {
        for (k, subject) in SUBJECTS.iter().enumerate() {
            match style {
                None => candidates.push(format!("{subject} {action}")),
                Some((manners, adjective)) => {
                    candidates.push(format!(
                        "{subject} {action} {}",
                        manners[(i + k) % manners.len()]
                    ));
                    if k == 0 {
                        let article = if adjective.starts_with(['a', 'e', 'i', 'o', 'u']) {
                            "an"
                        } else {
                            "a"
                        };
                        candidates.push(format!("{article} {adjective} person {action}"));
                    }
                }
            }
        }
    }
    let mut h = stable_hash(seed);
    let mut out: Vec<String> = Vec::new();
    while out.len() < count.min(candidates.len()) {
        h = h
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        let pick = &candidates[(h >> 33) as usize % candidates.len()];
        if !out.contains(pick) {
            out.push(pick.clone());
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn subjects_become_a_person_and_the_rest_stays() {
        assert_eq!(with_plain_subject("someone waves"), "a person waves");
        assert_eq!(
            with_plain_subject("a human jumps high"),
            "a person jumps high"
        );
        assert_eq!(with_plain_subject("a person bows"), "a person bows");
        assert_eq!(
            with_plain_subject("an old person bows"),
            "an old person bows"
        );
        assert_eq!(with_plain_subject("someoneX waves"), "someoneX waves");
    }

    #[test]
    fn mirroring_swaps_sides() {
        assert_eq!(mirror_content("wave-left-hand"), "wave-right-hand");
        assert_eq!(mirror_content("walk-turn-right"), "walk-turn-left");
        assert_eq!(mirror_content("bow"), "bow");
    }

    #[test]
    fn captions_are_distinct_deterministic_and_on_topic() {
        let a = global_captions("wave-left-hand", "tired", "clip_001", 4);
        assert_eq!(a.len(), 4);
        assert_eq!(a, global_captions("wave-left-hand", "tired", "clip_001", 4));
        let mut sorted = a.clone();
        sorted.sort();
        sorted.dedup();
        assert_eq!(sorted.len(), 4);
        assert!(
            a.iter().all(|c| c.contains("left") && !c.contains("right")),
            "{a:?}"
        );
    }

    #[test]
    fn unknown_labels_still_get_words() {
        let c = global_captions("cartwheel", "normal", "x", 2);
        assert!(c.iter().all(|c| c.contains("cartwheel")), "{c:?}");
        let c = global_captions("moonwalk", "normal", "x", 2);
        assert!(c.iter().all(|c| c.contains("moonwalk")), "{c:?}");
    }

    #[test]
    fn sided_labels_name_their_side_and_mirror() {
        for content in [
            "kick-left-leg",
            "punch-left-hand",
            "kick-ball-left-leg",
            "put-down-left-hand",
            "throw-left-hand",
            "spin-kick-left-leg",
        ] {
            let c = global_captions(content, "normal", "clip", 3);
            assert_eq!(c.len(), 3, "{content}: {c:?}");
            assert!(
                c.iter().all(|c| c.contains("left") && !c.contains("right")),
                "{content}: {c:?}"
            );
            let m = global_captions(&mirror_content(content), "normal", "clip", 3);
            assert!(
                m.iter().all(|c| c.contains("right") && !c.contains("left")),
                "{content}: {m:?}"
            );
        }
        assert!(global_captions("kick-left-leg", "normal", "x", 3)
            .iter()
            .all(|c| c.contains("kick")));
    }
}
