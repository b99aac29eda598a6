//! Behaviour tests on synthetic motions built with forward kinematics.

use super::*;
use crate::geom::{self, Quat, Vec3};
use crate::skeleton::{self, joint, BodyPart, Offsets, Pose, CHAINS, NUM_JOINTS, RAW_OFFSETS};
use std::f64::consts::PI;

/// Bone lengths (metres) of a roughly 1.6 m adult, indexed by child joint.
const LENGTHS: [f64; NUM_JOINTS] = [
    0.0, 0.09, 0.09, 0.10, 0.40, 0.40, 0.13, 0.40, 0.40, 0.14, 0.14, 0.14, 0.14, 0.08, 0.08, 0.12,
    0.11, 0.11, 0.27, 0.27, 0.25, 0.25,
];
/// Pelvis height that puts the standing toes just above y = 0.
const PELVIS_HEIGHT: f64 = 0.86;

const UP: Vec3 = [0.0, 1.0, 0.0];
const DOWN: Vec3 = [0.0, -1.0, 0.0];
const FORWARD: Vec3 = [0.0, 0.0, 1.0];
const BACK: Vec3 = [0.0, 0.0, -1.0];
const LEFT: Vec3 = [1.0, 0.0, 0.0];
const RIGHT: Vec3 = [-1.0, 0.0, 0.0];

/// Direction of every bone (parent to child) in the body frame, whose axes are the world's when
/// the body faces +Z: +X left, +Y up, +Z forward.
type Dirs = [Vec3; NUM_JOINTS];

/// Standing upright: legs straight down, toes forward and a little down, head above the neck,
/// shoulders out from the collars, arms hanging.
fn standing() -> Dirs {
    let mut d = RAW_OFFSETS;
    d[joint::L_FOOT] = [0.0, -0.4, 1.0];
    d[joint::R_FOOT] = [0.0, -0.4, 1.0];
    d[joint::HEAD] = UP;
    d[joint::L_SHOULDER] = [1.0, 0.3, 0.0];
    d[joint::R_SHOULDER] = [-1.0, 0.3, 0.0];
    d
}

/// A hanging bone swung `deg` degrees from straight down towards `toward` (90 = horizontal,
/// 180 = straight up).
fn swing(deg: f64, toward: Vec3) -> Vec3 {
    let a = deg.to_radians();
    geom::add(geom::scale(DOWN, a.cos()), geom::scale(toward, a.sin()))
}

/// The rotation taking `from` onto `to`, also for opposite directions (where the shortest arc
/// is not unique and `Quat::between` gives up).
fn rotation_to(from: Vec3, to: Vec3) -> Quat {
    let (a, b) = (geom::normalize(from), geom::normalize(to));
    if geom::dot(a, b) < -0.999_999 {
        let helper = if a[0].abs() < 0.9 { LEFT } else { FORWARD };
        Quat::from_axis_angle(geom::cross(a, helper), PI)
    } else {
        Quat::between(a, b)
    }
}

/// One pose through `skeleton::forward_kinematics`: bones along `dirs` in the body frame, the
/// body turned by `yaw` radians about +Y (0 faces +Z, π/2 faces +X), pelvis at `root`.
fn pose(dirs: &Dirs, yaw: f64, root: Vec3) -> Pose {
    let offsets = Offsets(std::array::from_fn(|j| {
        geom::scale(RAW_OFFSETS[j], LENGTHS[j])
    }));
    let facing = Quat::from_yaw(yaw);
    let mut rots = [Quat::IDENTITY; NUM_JOINTS];
    rots[0] = facing;
    for chain in CHAINS {
        // Forward kinematics accumulates each chain from the root rotation alone.
        let mut acc = facing;
        for pair in chain.windows(2) {
            let child = pair[1];
            let global = facing.mul(rotation_to(RAW_OFFSETS[child], dirs[child]));
            let local = acc.inv().mul(global);
            rots[child] = local;
            acc = acc.mul(local);
        }
    }
    skeleton::forward_kinematics(&[rots], &offsets, &[root])[0]
}

fn at_rest(dirs: &Dirs) -> Pose {
    pose(dirs, 0.0, [0.0, PELVIS_HEIGHT, 0.0])
}

/// `frames` poses at 20 fps from a function of (frame index, time in seconds).
fn motion(frames: usize, f: impl Fn(usize, f64) -> Pose) -> Vec<Pose> {
    (0..frames).map(|i| f(i, i as f64 / 20.0)).collect()
}

fn held(dirs: &Dirs, frames: usize) -> Vec<Pose> {
    vec![at_rest(dirs); frames]
}

/// A walk cycle (legs and arms swinging at 1 Hz, so two steps a second) with the pelvis moving
/// at `velocity` m/s while the body keeps facing +Z.
fn walk_pose(t: f64, velocity: Vec3) -> Pose {
    let phase = (2.0 * PI * t).sin();
    let mut d = standing();
    d[joint::L_KNEE] = swing(20.0 * phase, FORWARD);
    d[joint::L_ANKLE] = d[joint::L_KNEE];
    d[joint::R_KNEE] = swing(-20.0 * phase, FORWARD);
    d[joint::R_ANKLE] = d[joint::R_KNEE];
    d[joint::L_ELBOW] = swing(-15.0 * phase, FORWARD);
    d[joint::L_WRIST] = d[joint::L_ELBOW];
    d[joint::R_ELBOW] = swing(15.0 * phase, FORWARD);
    d[joint::R_WRIST] = d[joint::R_ELBOW];
    let shift = geom::scale(velocity, t);
    pose(&d, 0.0, geom::add([0.0, PELVIS_HEIGHT, 0.0], shift))
}

fn walk(frames: usize, velocity: Vec3) -> Vec<Pose> {
    motion(frames, |_, t| walk_pose(t, velocity))
}

fn sentence(poses: &[Pose], part: BodyPart) -> String {
    let all = part_sentences(poses);
    all.into_iter()
        .find(|(p, _)| *p == part)
        .map(|(_, s)| s)
        .expect("every part has a sentence")
}

fn swap_sides(s: &str) -> String {
    s.replace("left", "\u{0}")
        .replace("right", "left")
        .replace('\u{0}', "right")
}

fn raised_left_arm() -> Dirs {
    let mut d = standing();
    d[joint::L_ELBOW] = UP;
    d[joint::L_WRIST] = UP;
    d
}

#[test]
fn standing_pose_is_straight_hanging_grounded_and_still() {
    let p = at_rest(&standing());
    let c = frame_codes(&p, floor_height(&[p]));
    for leg in [c.left_leg, c.right_leg] {
        assert_eq!(leg.knee, Bend::Straight);
        assert!(leg.knee_angle_deg > 179.0);
        assert_eq!(leg.thigh, Orientation::Vertical);
        assert_eq!(leg.shin, Orientation::Vertical);
        assert!(leg.foot_on_ground);
        assert!(!leg.knee_on_ground);
        assert_eq!(leg.ankle_vs_other, Depth::Level);
    }
    for arm in [c.left_arm, c.right_arm] {
        assert_eq!(arm.elbow, Bend::Straight);
        assert_eq!(arm.wrist_vs_head, Vertical::Below);
        assert_eq!(arm.wrist_vs_shoulder, Vertical::Below);
        assert_eq!(arm.upper_arm, Orientation::Vertical);
        assert_eq!(arm.forearm, Orientation::Vertical);
        assert_eq!(arm.wrist_depth, Depth::Level);
        assert_eq!(arm.wrist_to_head, Distance::Spread);
        assert!(!arm.crossed);
    }
    assert_eq!(c.left_arm.wrist_side, Side::Left);
    assert_eq!(c.right_arm.wrist_side, Side::Right);
    assert_eq!(c.wrists, Distance::ShoulderWidth);
    assert_eq!(c.ankles, Distance::ShoulderWidth);

    let poses = held(&standing(), 40);
    let d = describe_window(&poses);
    assert_eq!(d.pace, Pace::Still);
    assert_eq!(d.travel, None);
    assert_eq!(d.jumps, 0);
    assert_eq!(d.torso, Torso::Upright);
    assert_eq!(d.level, Level::Steady);
    assert!(d.turn_deg.abs() < 1e-9);
    assert_eq!(d.left_arm.height, ArmHeight::Low);
    assert!((d.left_leg.ground_fraction - 1.0).abs() < 1e-12);

    let s = part_sentences(&poses);
    assert_eq!(
        s[0],
        (BodyPart::LeftArm, "the left arm hangs at the side".into())
    );
    assert_eq!(
        s[1],
        (BodyPart::RightArm, "the right arm hangs at the side".into())
    );
    assert_eq!(
        s[2],
        (BodyPart::LeftLeg, "the left leg stands still".into())
    );
    assert_eq!(
        s[3],
        (BodyPart::RightLeg, "the right leg stands still".into())
    );
    assert_eq!(describe_motion(&poses), "A person stands still.");
}

#[test]
fn raised_left_arm_is_above_the_head_and_only_the_left_arm_says_so() {
    let p = at_rest(&raised_left_arm());
    let c = frame_codes(&p, floor_height(&[p]));
    assert_eq!(c.left_arm.wrist_vs_head, Vertical::Above);
    assert_eq!(c.left_arm.wrist_vs_shoulder, Vertical::Above);
    assert_eq!(c.left_arm.upper_arm, Orientation::Vertical);
    assert_eq!(c.right_arm.wrist_vs_head, Vertical::Below);

    let poses = held(&raised_left_arm(), 30);
    let d = describe_window(&poses);
    assert_eq!(d.left_arm.height, ArmHeight::AboveHead);
    assert!(!d.left_arm.waves, "a still raised arm is not a wave");
    assert_eq!(d.right_arm.height, ArmHeight::Low);

    let left = sentence(&poses, BodyPart::LeftArm);
    let right = sentence(&poses, BodyPart::RightArm);
    assert_eq!(left, "the left arm is raised above the head");
    assert!(!right.contains("raised"), "{right}");
    assert_eq!(right, "the right arm hangs at the side");
    let whole = describe_motion(&poses);
    assert!(
        whole.contains("The left arm is raised above the head."),
        "{whole}"
    );
    assert!(!whole.contains("right arm"), "{whole}");
}

#[test]
fn mirrored_motion_swaps_left_and_right_sentences() {
    let mut d = raised_left_arm();
    d[joint::L_KNEE] = FORWARD;
    d[joint::L_ANKLE] = DOWN;
    let poses = held(&d, 30);
    let original = part_sentences(&poses);
    assert_eq!(original[2].1, "the left leg is lifted forward");
    assert_eq!(original[3].1, "the right leg stands still");

    let mirrored = part_sentences(&skeleton::mirror_poses(&poses));
    for (part, text) in &original {
        let (_, other) = mirrored
            .iter()
            .find(|(p, _)| *p == part.mirrored())
            .expect("all parts present");
        assert_eq!(other, &swap_sides(text));
    }
    assert_eq!(
        describe_motion(&skeleton::mirror_poses(&poses)),
        swap_sides(&describe_motion(&poses))
    );

    let c = frame_codes(&skeleton::mirror_poses(&poses)[0], 0.0);
    assert_eq!(c.right_arm.wrist_vs_head, Vertical::Above);
    assert_eq!(c.left_arm.wrist_vs_head, Vertical::Below);
}

#[test]
fn root_moving_forward_walks_forward() {
    let poses = walk(60, [0.0, 0.0, 1.2]);
    let d = describe_window(&poses);
    assert!((d.speed_mps - 1.2).abs() < 0.05, "{}", d.speed_mps);
    assert_eq!(d.pace, Pace::Walking);
    assert_eq!(d.travel, Some(Travel::Forward));
    assert_eq!(d.jumps, 0);
    assert!(!d.left_arm.waves);
    assert!(d.left_arm.swings);
    assert_eq!(
        sentence(&poses, BodyPart::LeftLeg),
        "the left leg walks forward"
    );
    assert_eq!(
        sentence(&poses, BodyPart::RightLeg),
        "the right leg walks forward"
    );
    assert_eq!(
        sentence(&poses, BodyPart::LeftArm),
        "the left arm swings back and forth"
    );
    assert_eq!(describe_motion(&poses), "A person walks forward.");
}

#[test]
fn root_moving_back_while_facing_forward_walks_backward() {
    let poses = walk(60, [0.0, 0.0, -1.0]);
    let d = describe_window(&poses);
    assert_eq!(d.travel, Some(Travel::Backward));
    assert_eq!(
        sentence(&poses, BodyPart::LeftLeg),
        "the left leg walks backward"
    );
    assert!(describe_motion(&poses).starts_with("A person walks backward"));
}

#[test]
fn moving_towards_plus_x_while_facing_plus_z_steps_left() {
    let poses = walk(60, [0.8, 0.0, 0.0]);
    assert_eq!(describe_window(&poses).travel, Some(Travel::Left));
    assert_eq!(
        sentence(&poses, BodyPart::RightLeg),
        "the right leg steps to the left"
    );
    let mirrored = skeleton::mirror_poses(&poses);
    assert_eq!(describe_window(&mirrored).travel, Some(Travel::Right));
}

#[test]
fn raised_forearm_swinging_sideways_is_a_wave() {
    let poses = motion(40, |_, t| {
        let mut d = standing();
        d[joint::L_ELBOW] = [1.0, 1.0, 0.0];
        let phi = 0.5 * (2.0 * PI * 1.5 * t).sin();
        d[joint::L_WRIST] = [phi.sin(), phi.cos(), 0.0];
        at_rest(&d)
    });
    let d = describe_window(&poses);
    assert!(d.left_arm.waves);
    assert!(
        d.left_arm.raised_reversals >= 4,
        "{}",
        d.left_arm.raised_reversals
    );
    assert_eq!(d.left_arm.height, ArmHeight::AboveHead);
    assert!(!d.right_arm.waves);
    assert_eq!(
        sentence(&poses, BodyPart::LeftArm),
        "the left arm is raised above the head and waves"
    );
    assert_eq!(
        sentence(&poses, BodyPart::RightArm),
        "the right arm hangs at the side"
    );
    assert_eq!(
        describe_motion(&poses),
        "A person stands still. The left arm is raised above the head and waves."
    );
}

#[test]
fn facing_turning_from_plus_z_to_plus_x_is_a_left_turn() {
    let n = 40;
    let turning = |end_yaw: f64| {
        motion(n, |i, _| {
            let yaw = end_yaw * i as f64 / (n - 1) as f64;
            pose(&standing(), yaw, [0.0, PELVIS_HEIGHT, 0.0])
        })
    };
    let poses = turning(PI / 2.0);
    let last = facing(&poses[n - 1]);
    assert!(geom::dist(last, [1.0, 0.0, 0.0]) < 1e-9, "ends facing +X");
    let d = describe_window(&poses);
    assert!((d.turn_deg - 90.0).abs() < 0.5, "{}", d.turn_deg);
    assert_eq!(d.pace, Pace::Still);
    assert_eq!(
        describe_motion(&poses),
        "A person turns left by about 90 degrees."
    );
    assert_eq!(
        sentence(&poses, BodyPart::LeftLeg),
        "the left leg pivots as the body turns left"
    );
    // The arms keep their place in the body frame while the body turns.
    assert_eq!(
        sentence(&poses, BodyPart::LeftArm),
        "the left arm hangs at the side"
    );

    let right = turning(-PI / 2.0);
    assert!((describe_window(&right).turn_deg + 90.0).abs() < 0.5);
    assert_eq!(
        describe_motion(&right),
        "A person turns right by about 90 degrees."
    );
}

#[test]
fn knee_and_elbow_bend_categories() {
    for (shin_from_down, expected) in [
        (10.0, Bend::Straight),
        (40.0, Bend::SlightlyBent),
        (70.0, Bend::PartiallyBent),
        (120.0, Bend::CompletelyBent),
    ] {
        let mut d = standing();
        d[joint::L_ANKLE] = swing(shin_from_down, BACK);
        d[joint::R_WRIST] = swing(shin_from_down, FORWARD);
        let c = frame_codes(&at_rest(&d), 0.0);
        assert_eq!(c.left_leg.knee, expected, "shin at {shin_from_down}°");
        assert!((c.left_leg.knee_angle_deg - (180.0 - shin_from_down)).abs() < 1e-6);
        assert_eq!(c.right_leg.knee, Bend::Straight);
        assert_eq!(c.right_arm.elbow, expected, "forearm at {shin_from_down}°");
        assert_eq!(c.left_arm.elbow, Bend::Straight);
    }
    assert_eq!(Bend::from_angle(160.5), Bend::Straight);
    assert_eq!(Bend::from_angle(89.0).as_str(), "completely bent");
}

#[test]
fn relative_positions_distances_and_orientations() {
    // Left forearm pointing across the body to the right, right forearm pointing forward,
    // left foot a step ahead.
    let mut d = standing();
    d[joint::L_WRIST] = RIGHT;
    d[joint::R_WRIST] = FORWARD;
    d[joint::L_KNEE] = swing(20.0, FORWARD);
    d[joint::L_ANKLE] = d[joint::L_KNEE];
    let c = frame_codes(&at_rest(&d), 0.0);
    assert!(c.left_arm.crossed);
    assert_eq!(c.left_arm.wrist_side, Side::Right);
    assert_eq!(c.left_arm.forearm, Orientation::Horizontal);
    assert_eq!(c.right_arm.wrist_depth, Depth::InFront);
    assert!(!c.right_arm.crossed);
    assert_eq!(c.left_leg.ankle_vs_other, Depth::InFront);
    assert_eq!(c.right_leg.ankle_vs_other, Depth::Behind);
    assert_eq!(c.left_leg.thigh, Orientation::Vertical);

    // Arms straight out to the sides (T pose), then one at 45°.
    let mut t = standing();
    for (j, side) in [
        (joint::L_ELBOW, LEFT),
        (joint::L_WRIST, LEFT),
        (joint::R_ELBOW, RIGHT),
        (joint::R_WRIST, RIGHT),
    ] {
        t[j] = side;
    }
    let c = frame_codes(&at_rest(&t), 0.0);
    assert_eq!(c.wrists, Distance::Wide);
    assert_eq!(c.left_arm.upper_arm, Orientation::Horizontal);
    assert_eq!(c.left_arm.wrist_vs_shoulder, Vertical::Level);
    t[joint::L_ELBOW] = swing(45.0, LEFT);
    assert_eq!(
        frame_codes(&at_rest(&t), 0.0).left_arm.upper_arm,
        Orientation::Diagonal
    );
    assert_eq!(Distance::from_metres(0.1), Distance::Close);
    assert_eq!(Distance::from_metres(0.7).as_str(), "spread");
}

#[test]
fn knee_near_the_floor_is_kneeling() {
    // Shins flat behind the knees, pelvis lowered so the knees are 5 cm above the floor.
    let mut d = standing();
    d[joint::L_ANKLE] = BACK;
    d[joint::R_ANKLE] = BACK;
    d[joint::L_FOOT] = BACK;
    d[joint::R_FOOT] = BACK;
    let p = pose(&d, 0.0, [0.0, 0.45, 0.0]);
    let c = frame_codes(&p, 0.0);
    assert!(c.left_leg.knee_on_ground && c.right_leg.knee_on_ground);
    assert_eq!(c.left_leg.knee, Bend::PartiallyBent);
    assert_eq!(c.left_leg.shin, Orientation::Horizontal);

    let poses = vec![p; 30];
    assert!(describe_window(&poses).left_leg.kneels);
    assert_eq!(
        sentence(&poses, BodyPart::LeftLeg),
        "the left leg kneels on the ground"
    );
    assert_eq!(
        describe_motion(&poses),
        "A person kneels. Both legs kneel on the ground."
    );
}

#[test]
fn both_feet_off_the_floor_with_the_pelvis_up_is_a_jump() {
    let poses = motion(40, |i, _| {
        let x = (i as f64 - 20.0) / 6.0;
        let lift = (0.3 * (1.0 - x * x)).max(0.0);
        pose(&standing(), 0.0, [0.0, PELVIS_HEIGHT + lift, 0.0])
    });
    let d = describe_window(&poses);
    assert_eq!(d.jumps, 1);
    assert_eq!(describe_motion(&poses), "A person jumps in place.");
    assert_eq!(
        sentence(&poses, BodyPart::RightLeg),
        "the right leg jumps off the ground"
    );
    // A running flight phase of two frames is not a jump.
    let short = motion(40, |i, _| {
        let lift = if (20..22).contains(&i) { 0.15 } else { 0.0 };
        pose(&standing(), 0.0, [0.0, PELVIS_HEIGHT + lift, 0.0])
    });
    assert_eq!(describe_window(&short).jumps, 0);
}

#[test]
fn torso_tilting_forward_and_back_is_a_bow() {
    let poses = motion(40, |i, _| {
        let a = (60.0 * (PI * i as f64 / 39.0).sin()).to_radians();
        let mut d = standing();
        for j in [
            joint::SPINE1,
            joint::SPINE2,
            joint::SPINE3,
            joint::NECK,
            joint::HEAD,
        ] {
            d[j] = [0.0, a.cos(), a.sin()];
        }
        at_rest(&d)
    });
    let d = describe_window(&poses);
    assert_eq!(d.torso, Torso::Bows);
    assert!((d.max_forward_tilt_deg - 60.0).abs() < 1.0);
    assert_eq!(describe_motion(&poses), "A person bows.");
    assert_eq!(
        sentence(&poses, BodyPart::LeftLeg),
        "the left leg stays straight as the body bows"
    );
    // Half the bow: down and staying there.
    let down = &poses[..20];
    assert_eq!(describe_window(down).torso, Torso::BendsForward);
}

#[test]
fn fast_forward_leg_swing_is_a_kick() {
    let poses = motion(30, |i, _| {
        let phi = if (10..=18).contains(&i) {
            90.0 * (PI * (i as f64 - 10.0) / 8.0).sin()
        } else {
            0.0
        };
        let mut d = standing();
        d[joint::L_KNEE] = swing(phi, FORWARD);
        d[joint::L_ANKLE] = d[joint::L_KNEE];
        at_rest(&d)
    });
    let d = describe_window(&poses);
    assert_eq!(d.left_leg.lift, Some(LegDirection::Forward));
    assert!(d.left_leg.kicks);
    assert_eq!(d.right_leg.lift, None);
    assert_eq!(
        sentence(&poses, BodyPart::LeftLeg),
        "the left leg kicks forward"
    );
    assert_eq!(
        sentence(&poses, BodyPart::RightLeg),
        "the right leg stands still"
    );
    assert_eq!(
        describe_motion(&poses),
        "A person stands still. The left leg kicks forward."
    );
}

#[test]
fn long_motion_is_told_in_windows_without_repeats() {
    let poses: Vec<Pose> = (0..120)
        .map(|i| {
            if i < 60 {
                at_rest(&standing())
            } else {
                walk_pose((i - 60) as f64 / 20.0, [0.0, 0.0, 1.2])
            }
        })
        .collect();
    // The middle window is half standing, half walking: slower on average, but still the same
    // walk, told once.
    assert_eq!(
        sentence(&poses, BodyPart::LeftLeg),
        "the left leg stands still, then walks forward"
    );
    assert_eq!(
        describe_motion(&poses),
        "A person stands still, then walks forward."
    );

    // Twenty seconds of standing is still one short sentence.
    let long = held(&standing(), 400);
    assert_eq!(
        sentence(&long, BodyPart::LeftArm),
        "the left arm hangs at the side"
    );
    assert_eq!(describe_motion(&long), "A person stands still.");
}

#[test]
fn empty_and_single_frame_motions_do_not_panic() {
    assert_eq!(describe_motion(&[]), "A person stands still.");
    assert_eq!(describe_window(&[]).frames, 0);
    let one = held(&standing(), 1);
    assert_eq!(describe_window(&one).pace, Pace::Still);
    assert_eq!(
        sentence(&one, BodyPart::RightLeg),
        "the right leg stands still"
    );
}

#[test]
fn descriptors_serialize_to_json() {
    let d = describe_window(&held(&raised_left_arm(), 10));
    let json = serde_json::to_value(d).expect("serializable");
    assert_eq!(json["left_arm"]["height"], "above_head");
    assert_eq!(json["pace"], "still");
    let c = serde_json::to_value(frame_codes(&at_rest(&standing()), 0.0)).expect("ok");
    assert_eq!(c["left_leg"]["knee"], "straight");
}
