use super::*;

use crate::eval::probes::foot_skating;
use crate::skeleton::{
    forward_kinematics, Offsets, Rotations, NUM_JOINTS, PARENTS, REFERENCE_BONE_LENGTHS,
};

fn rot_x(deg: f64) -> Quat {
    Quat::from_axis_angle([1.0, 0.0, 0.0], deg.to_radians())
}

fn rot_z(deg: f64) -> Quat {
    Quat::from_axis_angle([0.0, 0.0, 1.0], deg.to_radians())
}

/// The reference skeleton posed by `rots`, lowest joint on the floor.
fn pose_from(rots: Rotations) -> Pose {
    let mut pose = forward_kinematics(&[rots], &Offsets::reference(), &[[0.0; 3]])[0];
    let low = lowest(&pose);
    shift_y(&mut pose, -low);
    pose
}

fn standing() -> Pose {
    pose_from([Quat::IDENTITY; NUM_JOINTS])
}

fn arms_out() -> Pose {
    let mut rots = [Quat::IDENTITY; NUM_JOINTS];
    rots[joint::L_ELBOW] = rot_z(90.0);
    rots[joint::R_ELBOW] = rot_z(-90.0);
    pose_from(rots)
}

/// Thighs raised `hip` degrees forward, knees bent `knee` degrees, feet flat, torso leaning
/// forward; pelvis above the origin as the posture solver leaves it, so the feet are ahead
/// of where they are standing.
fn bent(hip: f64, knee: f64, lean: f64) -> Pose {
    let mut rots = [Quat::IDENTITY; NUM_JOINTS];
    for (thigh, shin, foot) in [
        (joint::L_KNEE, joint::L_ANKLE, joint::L_FOOT),
        (joint::R_KNEE, joint::R_ANKLE, joint::R_FOOT),
    ] {
        rots[thigh] = rot_x(-hip);
        rots[shin] = rot_x(knee);
        rots[foot] = rot_x(hip - knee);
    }
    rots[joint::SPINE1] = rot_x(lean);
    pose_from(rots)
}

fn squat() -> Pose {
    bent(80.0, 110.0, 30.0)
}

fn crouch() -> Pose {
    bent(50.0, 90.0, 20.0)
}

/// On hands and knees: trunk pitched forward, thighs and arms vertical, shins and feet
/// flat behind; the pitch is chosen so hands and knees touch the floor together.
fn hands_and_knees() -> Pose {
    let build = |pitch: f64| {
        let mut rots = [Quat::IDENTITY; NUM_JOINTS];
        rots[0] = rot_x(pitch);
        for (thigh, shin, foot) in [
            (joint::L_KNEE, joint::L_ANKLE, joint::L_FOOT),
            (joint::R_KNEE, joint::R_ANKLE, joint::R_FOOT),
        ] {
            rots[thigh] = rot_x(-pitch);
            rots[shin] = rot_x(90.0);
            rots[foot] = rot_x(90.0);
        }
        rots[joint::L_ELBOW] = rot_x(-pitch);
        rots[joint::R_ELBOW] = rot_x(-pitch);
        pose_from(rots)
    };
    let gap = |p: &Pose| (p[joint::L_WRIST][1] - p[joint::L_KNEE][1]).abs();
    (0..=100)
        .map(|i| build(40.0 + 0.5 * i as f64))
        .min_by(|a, b| gap(a).total_cmp(&gap(b)))
        .unwrap()
}

/// Facing angle (radians from +Z towards +X) from the hips.
fn facing(pose: &Pose) -> f64 {
    let across = geom::sub(pose[joint::L_HIP], pose[joint::R_HIP]);
    let forward = geom::cross(across, [0.0, 1.0, 0.0]);
    forward[0].atan2(forward[2])
}

const FEET: [usize; 4] = [joint::L_ANKLE, joint::R_ANKLE, joint::L_FOOT, joint::R_FOOT];

/// How far any foot joint gets from where it started on the ground plane, and how far it
/// leaves the range of heights it has in the frames `keys` (where the keys are held).
fn foot_drift(motion: &[Pose], keys: &[usize]) -> (f64, f64) {
    let mut drift = (0.0f64, 0.0f64);
    for f in FEET {
        let heights = keys.iter().map(|&k| motion[k][f][1]);
        let low = heights.clone().fold(f64::INFINITY, f64::min);
        let high = heights.fold(f64::NEG_INFINITY, f64::max);
        for pose in motion {
            drift.0 = drift.0.max(dist_xz(pose[f], motion[0][f]));
            drift.1 = drift.1.max(low - pose[f][1]).max(pose[f][1] - high);
        }
    }
    drift
}

fn arms_motion() -> Vec<Pose> {
    go(&[
        KeyPose::new(standing(), 0.0, 0.5),
        KeyPose::new(arms_out(), 1.0, 0.5),
        KeyPose::new(standing(), 1.0, 0.3),
    ])
}

fn squats() -> Vec<Pose> {
    go(&repeat(
        &[
            KeyPose::new(standing(), 1.0, 0.3),
            KeyPose::new(squat(), 1.0, 0.3),
        ],
        3,
    ))
}

fn spin() -> Vec<Pose> {
    go(&[
        KeyPose::new(standing(), 0.0, 0.2),
        KeyPose {
            turn_deg: 360.0,
            ..KeyPose::new(standing(), 2.0, 0.2)
        },
    ])
}

fn jump() -> Vec<Pose> {
    go(&[
        KeyPose::new(standing(), 0.0, 0.3),
        KeyPose::new(crouch(), 0.6, 0.2),
        KeyPose {
            motion: Transition::Flight { apex_m: 0.4 },
            ..KeyPose::new(standing(), 0.3, 0.8)
        },
    ])
}

fn crawl_keys() -> Vec<KeyPose> {
    let stride = KeyPose {
        travel: [0.0, 0.2],
        ..KeyPose::new(hands_and_knees(), 0.8, 0.0)
    };
    repeat(&[stride, stride], 3)
}

fn eased_motions() -> Vec<(&'static str, Vec<Pose>)> {
    vec![
        ("arms", arms_motion()),
        ("squats", squats()),
        ("spin", spin()),
        ("crawl", go(&crawl_keys())),
    ]
}

#[test]
fn bones_keep_the_reference_lengths() {
    let mut all = eased_motions();
    all.push(("jump", jump()));
    for (name, motion) in all {
        assert!(!motion.is_empty(), "{name}");
        for (f, pose) in motion.iter().enumerate() {
            for j in 1..NUM_JOINTS {
                let parent = PARENTS[j].unwrap();
                let length = geom::dist(pose[j], pose[parent]);
                let error = (length - REFERENCE_BONE_LENGTHS[j]).abs();
                assert!(error < 1e-3, "{name} frame {f} bone {j}: off by {error}");
            }
        }
    }
}

#[test]
fn nothing_goes_under_the_floor() {
    let mut all = eased_motions();
    all.push(("jump", jump()));
    for (name, motion) in all {
        let low = motion.iter().map(lowest).fold(f64::INFINITY, f64::min);
        assert!(low > -0.02, "{name}: lowest joint at {low}");
    }
}

#[test]
fn a_hold_keeps_the_pose_still() {
    let motion = go(&[
        KeyPose::new(standing(), 0.0, 1.0),
        KeyPose::new(arms_out(), 0.8, 1.0),
    ]);
    // 1 s hold, 0.8 s transition, 1 s hold: 57 frames.
    assert_eq!(motion.len(), 57);
    let first_hold = &motion[..=20];
    let last_hold = &motion[36..];
    for hold in [first_hold, last_hold] {
        for pose in hold {
            let moved = pose
                .iter()
                .zip(&hold[0])
                .map(|(a, b)| geom::dist(*a, *b))
                .fold(0.0, f64::max);
            assert!(moved < 1e-9, "moved {moved} during a hold");
        }
    }
    // The first frame is the key itself: at the origin, facing +Z, on the floor.
    let start = standing();
    for (a, b) in motion[0].iter().zip(&start) {
        assert!(geom::dist(*a, *b) < 1e-6);
    }
    // The held end is the second key (arms out sideways at shoulder height).
    let end = motion.last().unwrap();
    assert!((end[joint::L_WRIST][1] - end[joint::L_SHOULDER][1]).abs() < 1e-6);
}

#[test]
fn transitions_ease_in_and_out() {
    let motion = arms_motion();
    // The transition runs from frame 10 to frame 30: the wrist starts and stops gently.
    let speed = |f: usize| geom::dist(motion[f][joint::L_WRIST], motion[f + 1][joint::L_WRIST]);
    assert!(speed(9) < 1e-9 && speed(30) < 1e-9);
    assert!(speed(10) < 0.15 * speed(19) && speed(29) < 0.15 * speed(19));
}

#[test]
fn a_full_spin_passes_through_half_and_ends_where_it_began() {
    let motion = spin();
    let yaws: Vec<f64> = motion.iter().map(facing).collect();
    assert!(yaws[0].abs() < 1e-6);
    assert!(
        yaws.last().unwrap().cos() > 0.9999,
        "ends at {}",
        yaws.last().unwrap()
    );
    assert!(
        yaws.iter().any(|y| y.cos() < -0.99),
        "never faced backwards"
    );
    let mut turned = 0.0;
    for w in yaws.windows(2) {
        let mut d = w[1] - w[0];
        while d > std::f64::consts::PI {
            d -= std::f64::consts::TAU;
        }
        while d < -std::f64::consts::PI {
            d += std::f64::consts::TAU;
        }
        turned += d;
    }
    assert!(
        (turned - std::f64::consts::TAU).abs() < 0.01,
        "turned {turned}"
    );
    // The body spins in place.
    let start = motion[0][joint::PELVIS];
    for pose in &motion {
        assert!(dist_xz(pose[joint::PELVIS], start) < 0.01);
    }
}

#[test]
fn a_left_turn_with_travel_faces_and_moves_as_asked() {
    let motion = go(&[
        KeyPose::new(standing(), 0.0, 0.0),
        KeyPose {
            turn_deg: 90.0,
            travel: [0.0, 0.5],
            ..KeyPose::new(standing(), 1.5, 0.2)
        },
        KeyPose {
            travel: [0.0, 0.4],
            ..KeyPose::new(standing(), 1.0, 0.2)
        },
    ]);
    let end = motion.last().unwrap();
    // Turning left from +Z faces +X; the second stride goes along +X.
    assert!((facing(end) - std::f64::consts::FRAC_PI_2).abs() < 1e-6);
    let pelvis = end[joint::PELVIS];
    assert!((pelvis[0] - 0.4).abs() < 1e-6 && (pelvis[2] - 0.5).abs() < 1e-6);
    assert!(foot_skating(&motion) == 0.0);
}

#[test]
fn a_jump_flies_to_its_apex_and_lands() {
    let motion = jump();
    let stand = standing()[joint::PELVIS][1];
    let (top, peak) = motion
        .iter()
        .enumerate()
        .max_by(|a, b| a.1[joint::PELVIS][1].total_cmp(&b.1[joint::PELVIS][1]))
        .unwrap();
    let rise = peak[joint::PELVIS][1] - stand;
    assert!((rise - 0.4).abs() < 0.02, "pelvis rose {rise}");
    assert!(
        lowest(peak) > 0.05,
        "lowest joint at {} at the apex",
        lowest(peak)
    );
    // Airborne about as long as the apex demands: 2·√(2·0.4/9.81) s ≈ 11.4 frames.
    let airborne = motion.iter().filter(|p| lowest(p) > 0.01).count();
    assert!((9..=13).contains(&airborne), "{airborne} frames airborne");
    assert!(top > 20 && top < motion.len() - 10);
    // It lands and settles back in the key, on the floor where it took off.
    let end = motion.last().unwrap();
    assert!((end[joint::PELVIS][1] - stand).abs() < 1e-3);
    assert!(lowest(end).abs() < 1e-9);
    assert!(dist_xz(end[joint::L_ANKLE], motion[0][joint::L_ANKLE]) < 1e-6);

    // A half-turn jump forward turns and travels in the air and lands facing back.
    let motion = go(&[
        KeyPose::new(standing(), 0.0, 0.2),
        KeyPose::new(crouch(), 0.6, 0.1),
        KeyPose {
            motion: Transition::Flight { apex_m: 0.3 },
            turn_deg: 180.0,
            travel: [0.0, 0.5],
            ..KeyPose::new(standing(), 0.3, 0.5)
        },
    ]);
    let end = motion.last().unwrap();
    assert!(facing(end).cos() < -0.9999, "faces {}", facing(end));
    let moved = end[joint::PELVIS][2] - motion[0][joint::PELVIS][2];
    assert!((moved - 0.5).abs() < 0.15, "moved {moved}");
    let airborne: Vec<&Pose> = motion.iter().filter(|p| lowest(p) > 0.01).collect();
    let turned = |p: &Pose| facing(p).cos();
    assert!(turned(airborne[0]) > 0.9 && turned(airborne[airborne.len() - 1]) < -0.9);
}

#[test]
fn planted_feet_do_not_skate() {
    // Standing and squatting, the reference skeleton's right foot hangs 1 cm and 0.65 cm
    // above the floor (its right leg is shorter): a planted foot may only move between
    // the heights the keys give it (frame 28 is in the first squat's hold).
    for (name, motion, keys) in [
        ("arms", arms_motion(), vec![0]),
        ("squats", squats(), vec![0, 28]),
    ] {
        assert_eq!(foot_skating(&motion), 0.0, "{name}");
        let (across, up) = foot_drift(&motion, &keys);
        assert!(across < 1e-3, "{name}: feet slid {across} m");
        assert!(up < 1e-3, "{name}: feet rose or sank {up} m");
    }
    // The squats really squat.
    let motion = squats();
    let low = motion
        .iter()
        .map(|p| p[joint::PELVIS][1])
        .fold(f64::INFINITY, f64::min);
    assert!(low < standing()[joint::PELVIS][1] - 0.3);
}

#[test]
fn a_crawl_cycle_travels_the_sum_of_its_strides() {
    let keys = crawl_keys();
    assert_eq!(keys.len(), 7);
    let motion = go(&keys);
    let travel: f64 = keys[1..].iter().map(|k| k.travel[1]).sum();
    let start = motion[0][joint::PELVIS];
    let end = motion.last().unwrap()[joint::PELVIS];
    assert!(
        (end[2] - start[2] - travel).abs() < 1e-3,
        "moved {}",
        end[2] - start[2]
    );
    assert!((end[0] - start[0]).abs() < 1e-3);
    // Hands and feet step one at a time: they do not drag along the floor.
    assert_eq!(foot_skating(&motion), 0.0);
    let crawl = hands_and_knees();
    assert!(crawl[joint::L_WRIST][1] < contact_height(joint::L_WRIST));
    assert!(crawl[joint::L_ANKLE][1] < contact_height(joint::L_ANKLE));
}

#[test]
fn joints_never_move_too_fast_outside_flight() {
    for (name, motion) in eased_motions() {
        let fastest = max_joint_speed(&motion);
        assert!(fastest <= MAX_JOINT_SPEED + 1e-9, "{name}: {fastest} m/s");
    }
    // A transition asked to take no time is lengthened, not a teleport.
    let motion = go(&[
        KeyPose::new(standing(), 0.0, 0.0),
        KeyPose::new(squat(), 0.0, 0.0),
    ]);
    assert!(motion.len() > 4, "{} frames", motion.len());
    assert!(max_joint_speed(&motion) <= MAX_JOINT_SPEED + 1e-9);
    assert_eq!(foot_skating(&motion), 0.0);
}

#[test]
fn odd_input_gives_a_finite_motion() {
    assert!(go(&[]).is_empty());
    assert!(repeat(&[], 3).is_empty());
    assert!(repeat(&[KeyPose::new(standing(), 1.0, 0.0)], 0).is_empty());
    assert_eq!(go(&[KeyPose::new(standing(), 0.0, 0.0)]).len(), 1);
    let mut broken = standing();
    broken[3][1] = f64::NAN;
    let weird = [
        KeyPose::new(standing(), f64::NAN, -1.0),
        KeyPose {
            turn_deg: f64::INFINITY,
            travel: [f64::NAN, 1e300],
            ..KeyPose::new(broken, -5.0, f64::INFINITY)
        },
        KeyPose {
            motion: Transition::Flight { apex_m: f64::NAN },
            ..KeyPose::new([[0.0; 3]; NUM_JOINTS], 0.0, 0.0)
        },
        KeyPose {
            motion: Transition::Flight { apex_m: 1e9 },
            turn_deg: -720.0,
            ..KeyPose::new([[1e200; 3]; NUM_JOINTS], 0.0, 0.1)
        },
        KeyPose {
            motion: Transition::Flight { apex_m: -1.0 },
            ..KeyPose::new(hands_and_knees(), 0.0, 0.0)
        },
    ];
    let motion = go(&weird);
    assert!(!motion.is_empty());
    assert!(motion.len() as f64 <= MAX_SECONDS * FPS + 1.0);
    assert!(motion.iter().flatten().flatten().all(|c| c.is_finite()));
    assert!(motion.iter().map(lowest).fold(f64::INFINITY, f64::min) > -0.02);
    assert_eq!(go(&weird), motion, "not deterministic");
    assert_eq!(repeat(&weird, usize::MAX).len(), MAX_REPEAT_KEYS);
}

#[test]
fn a_solved_squat_keeps_its_toes_planted() {
    // Keys as the posture solver makes them: each with its pelvis above the origin, so the
    // squat's feet are not where the standing feet are until `go` sets them there.
    use crate::posture::{script::PostureScript, solver};
    let stand = solver::pose_of(&solver::rest_angles());
    let script = PostureScript::parse(
        r#"{"name":"squat","constraints":[
        {"kind":"level","is":"crouching"},
        {"kind":"bend","joint":"left_knee","is":"completely_bent"},
        {"kind":"bend","joint":"right_knee","is":"completely_bent"},
        {"kind":"orientation","limb":"left_thigh","is":"horizontal"},
        {"kind":"orientation","limb":"right_thigh","is":"horizontal"},
        {"kind":"contact","point":"left_foot","on_ground":true},
        {"kind":"contact","point":"right_foot","on_ground":true},
        {"kind":"lean","is":"forward"}]}"#,
    )
    .expect("a valid squat script");
    let squat = solver::solve(&script, None).pose;
    let motion = go(&repeat(
        &[KeyPose::new(stand, 1.0, 0.3), KeyPose::new(squat, 1.0, 0.3)],
        2,
    ));
    assert_eq!(foot_skating(&motion), 0.0);
    for toe in [joint::L_FOOT, joint::R_FOOT] {
        for pose in &motion {
            assert!(dist_xz(pose[toe], motion[0][toe]) <= PLANT_TOLERANCE);
        }
    }
    assert!(max_joint_speed(&motion) <= MAX_JOINT_SPEED + 1e-9);
    assert!(motion.iter().map(lowest).fold(f64::INFINITY, f64::min) > -0.02);
}
