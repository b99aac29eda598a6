//! The timeline the go stage plays: each key placed in the world (its shape, where its
//! supports stay on the ground, how it turns and travels) and in time, how every transition
//! keeps its contacts, and the frame at any time.

use super::limbs::{
    pinned, solve_on_targets, Limb, Target, LEFT_ARM, LEFT_LEG, LIMBS, RIGHT_ARM, RIGHT_LEG,
};
use super::*;
use crate::geom::{self, Quat, Vec3};
use crate::skeleton::{
    forward_kinematics, inverse_kinematics, joint, Offsets, Pose, Rotations, NUM_JOINTS,
};

#[derive(Clone, Copy)]
struct Flight {
    /// Take-off (and landing) vertical speed, m/s.
    v0: f64,
    /// Seconds airborne.
    time: f64,
}

struct Landing {
    time: f64,
    v0: f64,
    /// Time constant of the dip, seconds.
    tau: f64,
}

/// One key, placed in the world and in time.
pub(super) struct Key {
    /// Local bone rotations; the root's is the identity (facing is `yaw`).
    rots: Rotations,
    /// Pelvis in the key's own frame: ground offset x, height, ground offset z.
    pelvis: Vec3,
    /// The key's pose in the world.
    world: Pose,
    contact: [bool; NUM_JOINTS],
    /// Facing (radians about +Y from +Z) and ground origin of the key's frame.
    yaw: f64,
    ground: Vec3,
    /// Ground origin at take-off, for a key reached by a flight.
    takeoff: Vec3,
    /// Facing change from the previous key (radians).
    turn: f64,
    /// Eased transition, or push-off for a flight (seconds).
    trans: f64,
    hold: f64,
    flight: Option<Flight>,
    /// Time the key is reached (seconds from the start).
    pub(super) reached: f64,
}

/// What a limb does during a transition.
#[derive(Clone, Copy, PartialEq)]
enum LimbMode {
    /// Follows the body.
    Free,
    /// Stays where it is on the ground.
    Planted,
    /// Moves from its place in one key to its place in the next inside windows of the
    /// transition: `steps` windows of its own, interleaved with `of` limbs at position `slot`.
    /// `stepping` when it is on the ground at both ends (so it must lift to move). Its windows
    /// fill the transition after the share `wait` (0–1), where it stays at its first place.
    Moving {
        slot: usize,
        of: usize,
        steps: usize,
        stepping: bool,
        wait: f64,
    },
    /// On the ground when a jump starts: stays until take-off.
    PushOff,
}

/// How a transition keeps its contacts.
struct ContactPlan {
    /// Effectors on the ground in both keys: the pelvis height keeps them on the floor.
    supports: Vec<usize>,
    /// Pelvis height above the lowest support in each key.
    support_a: f64,
    support_b: f64,
    limbs: [LimbMode; 4],
}

pub(super) struct Timeline {
    offsets: Offsets,
    pub(super) keys: Vec<Key>,
    /// `plans[b]` for the transition into key `b` (`plans[0]` unused).
    plans: Vec<ContactPlan>,
    landings: Vec<Landing>,
    pub(super) total: f64,
}

fn clamp_key_seconds(s: f64) -> f64 {
    if s.is_nan() {
        0.0
    } else {
        s.clamp(0.0, MAX_KEY_SECONDS)
    }
}

fn finite_or_zero(v: f64) -> f64 {
    if v.is_finite() {
        v
    } else {
        0.0
    }
}

fn flight_of(motion: Transition) -> Option<Flight> {
    match motion {
        Transition::Flight { apex_m } if apex_m >= MIN_APEX => {
            let apex = apex_m.min(MAX_APEX);
            let time = 2.0 * (2.0 * apex / GRAVITY).sqrt();
            Some(Flight {
                v0: GRAVITY * time / 2.0,
                time,
            })
        }
        _ => None,
    }
}

/// World position of the pelvis for a key frame at `ground` facing `yaw`.
fn root_position(ground: Vec3, yaw: f64, pelvis: Vec3, height: f64) -> Vec3 {
    let offset = yawed(yaw, [pelvis[0], 0.0, pelvis[2]]);
    [ground[0] + offset[0], height, ground[2] + offset[2]]
}

fn world_pose(rots: &Rotations, yaw: f64, root: Vec3, offsets: &Offsets) -> Pose {
    let mut rots = *rots;
    rots[0] = Quat::from_yaw(yaw);
    forward_kinematics(&[rots], offsets, &[root])[0]
}

/// A key pose's bone rotations, pelvis (ground offset x, height over the floor, ground offset
/// z) and joints in its own frame (facing +Z, lowest joint on the floor).
fn shape(pose: &Pose, offsets: &Offsets) -> (Rotations, Vec3, Pose) {
    let usable = pose
        .iter()
        .flatten()
        .all(|c| c.is_finite() && c.abs() <= MAX_COORDINATE);
    let pelvis_xz = if usable {
        [pose[0][0], pose[0][2]]
    } else {
        [0.0, 0.0]
    };
    let mut rots = if usable {
        inverse_kinematics(&[*pose], false)[0]
    } else {
        [Quat::IDENTITY; NUM_JOINTS]
    };
    rots[0] = Quat::IDENTITY;
    let body = world_pose(&rots, 0.0, [0.0; 3], offsets);
    let pelvis = [pelvis_xz[0], -lowest(&body), pelvis_xz[1]];
    (rots, pelvis, body.map(|p| geom::add(p, pelvis)))
}

/// Where the body must stand so that its supports do not move needlessly: the ground offset
/// (metres, x and z) to add to `prev.ground + travel` for a key of shape `local` facing `yaw`.
///
/// Key poses are solved independently, each with its pelvis above the origin, so a squat's
/// feet sit ahead of a stand's. The supports of the new key (joints on the ground in both keys)
/// are expected where the old ones were, turned about the old pelvis and moved by `travel`; the
/// offset is the one that meets that expectation for the most limbs (all supports together
/// first, then each limb's own), ties going to the smaller total miss.
fn align(prev: &Key, local: &Pose, contact: &[bool; NUM_JOINTS], yaw: f64, travel: Vec3) -> Vec3 {
    let pelvis = prev.world[joint::PELVIS];
    let turn = yaw - prev.yaw;
    let flat = |v: Vec3| [v[0], 0.0, v[2]];
    let misses: Vec<Vec<Vec3>> = LIMBS
        .iter()
        .map(|limb| {
            limb.effectors()
                .filter(|&e| prev.contact[e] && contact[e])
                .map(|e| {
                    let expected = geom::add(
                        geom::add(pelvis, yawed(turn, geom::sub(prev.world[e], pelvis))),
                        travel,
                    );
                    let placed =
                        geom::add(geom::add(prev.ground, travel), yawed(yaw, flat(local[e])));
                    flat(geom::sub(expected, placed))
                })
                .collect()
        })
        .collect();
    let mean = |v: &[Vec3]| {
        let sum = v.iter().fold([0.0; 3], |a, b| geom::add(a, *b));
        geom::scale(sum, 1.0 / v.len().max(1) as f64)
    };
    let all: Vec<Vec3> = misses.iter().flatten().copied().collect();
    if all.is_empty() {
        return [0.0; 3];
    }
    let score = |offset: Vec3| {
        let kept = misses
            .iter()
            .filter(|m| {
                !m.is_empty() && m.iter().all(|d| geom::dist(*d, offset) <= PLANT_TOLERANCE)
            })
            .count();
        let miss: f64 = all.iter().map(|d| geom::dist(*d, offset)).sum();
        (kept, miss)
    };
    let mut best = mean(&all);
    let mut best_score = score(best);
    for m in misses.iter().filter(|m| !m.is_empty()) {
        let offset = mean(m);
        let s = score(offset);
        if s.0 > best_score.0 || (s.0 == best_score.0 && s.1 < best_score.1 - 1e-9) {
            (best, best_score) = (offset, s);
        }
    }
    best
}

impl Timeline {
    pub(super) fn new(input: &[KeyPose]) -> Timeline {
        let mut timeline = Timeline {
            offsets: Offsets::reference(),
            keys: Vec::new(),
            plans: Vec::new(),
            landings: Vec::new(),
            total: 0.0,
        };
        let mut clock = 0.0;
        for (i, key) in input.iter().enumerate() {
            if i > 0 && clock >= MAX_SECONDS {
                break;
            }
            let (rots, pelvis, local) = shape(&key.pose, &timeline.offsets);
            let contact: [bool; NUM_JOINTS] =
                std::array::from_fn(|j| local[j][1] < contact_height(j));
            let (yaw, ground, takeoff, turn, flight) = match timeline.keys.last() {
                None => (0.0, [0.0; 3], [0.0; 3], 0.0, None),
                Some(prev) => {
                    let turn = finite_or_zero(key.turn_deg)
                        .clamp(-MAX_TURN_DEG, MAX_TURN_DEG)
                        .to_radians();
                    let [left, forward] = key
                        .travel
                        .map(|v| finite_or_zero(v).clamp(-MAX_TRAVEL, MAX_TRAVEL));
                    let travel = yawed(prev.yaw, [left, 0.0, forward]);
                    let yaw = prev.yaw + turn;
                    let ground = geom::add(
                        geom::add(prev.ground, travel),
                        align(prev, &local, &contact, yaw, travel),
                    );
                    // A jump takes off in its new shape from where it stands, still facing the
                    // old way; turn and travel happen in the air.
                    let takeoff = geom::add(
                        prev.ground,
                        align(prev, &local, &contact, prev.yaw, [0.0; 3]),
                    );
                    (yaw, ground, takeoff, turn, flight_of(key.motion))
                }
            };
            let root = root_position(ground, yaw, pelvis, pelvis[1]);
            timeline.keys.push(Key {
                world: world_pose(&rots, yaw, root, &timeline.offsets),
                rots,
                pelvis,
                contact,
                yaw,
                ground,
                takeoff,
                turn,
                trans: 0.0,
                hold: clamp_key_seconds(key.hold),
                flight,
                reached: 0.0,
            });
            if i == 0 {
                timeline.plans.push(ContactPlan {
                    supports: Vec::new(),
                    support_a: 0.0,
                    support_b: 0.0,
                    limbs: [LimbMode::Free; 4],
                });
            } else {
                let plan = timeline.plan(i);
                timeline.plans.push(plan);
                let least = if flight.is_some() {
                    MIN_PUSH_OFF
                } else {
                    MIN_TRANSITION
                };
                let asked = clamp_key_seconds(key.transition).max(least);
                timeline.keys[i].trans =
                    asked.max(timeline.shortest_duration(i).min(MAX_KEY_SECONDS));
            }
            let key = &mut timeline.keys[i];
            key.reached = clock + key.trans + key.flight.map_or(0.0, |f| f.time);
            clock = key.reached + key.hold;
            if let Some(f) = key.flight {
                timeline.landings.push(Landing {
                    time: key.reached,
                    v0: f.v0,
                    tau: (LANDING_DIP * std::f64::consts::E / f.v0).min(LANDING_TIME),
                });
            }
        }
        timeline.total = clock.min(MAX_SECONDS);
        timeline
    }

    /// Decides, for the transition into key `b`, which limbs stay, step or follow the body.
    fn plan(&self, b: usize) -> ContactPlan {
        let (ka, kb) = (&self.keys[b - 1], &self.keys[b]);
        // Knees and the pelvis carry weight too (kneeling, sitting, lying): the body's height
        // keeps them on the floor, though only hands and feet are pinned in place.
        let supports: Vec<usize> = LIMBS
            .iter()
            .flat_map(Limb::effectors)
            .chain([joint::L_KNEE, joint::R_KNEE, joint::PELVIS])
            .filter(|&e| ka.contact[e] && kb.contact[e])
            .collect();
        let support = |k: &Key| {
            supports
                .iter()
                .map(|&e| k.pelvis[1] - k.world[e][1])
                .fold(f64::NEG_INFINITY, f64::max)
        };
        let (support_a, support_b) = if supports.is_empty() {
            (0.0, 0.0)
        } else {
            (support(ka), support(kb))
        };
        let mut limbs = [LimbMode::Free; 4];
        if kb.flight.is_some() {
            for (mode, limb) in limbs.iter_mut().zip(&LIMBS) {
                if limb.effectors().any(|e| ka.contact[e]) {
                    *mode = LimbMode::PushOff;
                }
            }
        } else {
            let mut stepping = Vec::new();
            let mut stride = 0.0f64;
            for (li, limb) in LIMBS.iter().enumerate() {
                let on_a = limb.effectors().any(|e| ka.contact[e]);
                let on_b = limb.effectors().any(|e| kb.contact[e]);
                if !on_a && !on_b {
                    continue;
                }
                let shared: Vec<usize> = limb
                    .effectors()
                    .filter(|&e| ka.contact[e] && kb.contact[e])
                    .collect();
                let still = shared
                    .iter()
                    .all(|&e| dist_xz(ka.world[e], kb.world[e]) <= PLANT_TOLERANCE);
                if !shared.is_empty() && still && kb.turn.abs() <= PIVOT_DEG.to_radians() {
                    limbs[li] = LimbMode::Planted;
                } else if on_a && on_b {
                    stepping.push(li);
                    for e in limb.effectors() {
                        stride = stride.max(dist_xz(ka.world[e], kb.world[e]));
                    }
                } else {
                    // A hand or foot leaving the ground carries weight until the body has come
                    // down onto its next supports (standing to sitting or lying), rather than
                    // sliding out from under it.
                    limbs[li] = LimbMode::Moving {
                        slot: 0,
                        of: 1,
                        steps: 1,
                        stepping: false,
                        wait: if on_a { LEAVE_LATE } else { 0.0 },
                    };
                }
            }
            // Limbs step one at a time, the leading side first (a crawl's lateral sequence: leg,
            // then the arm on the same side).
            let order = if kb.turn >= 0.0 {
                [LEFT_LEG, LEFT_ARM, RIGHT_LEG, RIGHT_ARM]
            } else {
                [RIGHT_LEG, RIGHT_ARM, LEFT_LEG, LEFT_ARM]
            };
            let steps = (kb.turn.abs() / STEP_TURN_DEG.to_radians())
                .ceil()
                .max((stride / STEP_LENGTH).ceil())
                .clamp(1.0, MAX_STEPS as f64) as usize;
            let of = stepping.len();
            for (slot, &li) in order.iter().filter(|li| stepping.contains(li)).enumerate() {
                limbs[li] = LimbMode::Moving {
                    slot,
                    of,
                    steps,
                    stepping: true,
                    wait: 0.0,
                };
            }
        }
        ContactPlan {
            supports,
            support_a,
            support_b,
            limbs,
        }
    }

    /// The shape between keys `b − 1` and `b` at `sigma` (0–1) placed at `ground` facing `yaw`,
    /// pelvis `extra` metres above where it keeps the supports on the floor.
    fn body(&self, b: usize, sigma: f64, yaw: f64, ground: Vec3, extra: f64) -> Pose {
        let (ka, kb, plan) = (&self.keys[b - 1], &self.keys[b], &self.plans[b]);
        let rots: Rotations = std::array::from_fn(|j| ka.rots[j].slerp(kb.rots[j], sigma));
        let mut pose = world_pose(&rots, yaw, [0.0; 3], &self.offsets);
        let pelvis = geom::lerp(ka.pelvis, kb.pelvis, sigma);
        // Interpolated shapes put the feet at heights neither key has; measuring the support
        // height of the shape itself keeps them on the floor, and subtracting its interpolation
        // leaves both ends exactly at the keys' heights.
        let correction = if plan.supports.is_empty() {
            0.0
        } else {
            let support = plan
                .supports
                .iter()
                .map(|&e| -pose[e][1])
                .fold(f64::NEG_INFINITY, f64::max);
            support - (plan.support_a + (plan.support_b - plan.support_a) * sigma)
        };
        let root = root_position(ground, yaw, pelvis, pelvis[1] + correction + extra);
        for p in pose.iter_mut() {
            *p = geom::add(*p, root);
        }
        if plan.supports.is_empty() {
            // Nothing carries the body from one key to the next (standing to lying): it rests
            // on whatever is lowest rather than floating between the keys' heights.
            let low = lowest(&pose) - extra;
            if low > 0.0 {
                shift_y(&mut pose, -low);
            }
        }
        pose
    }

    /// Where the body is at `sigma` of an eased transition into `b`, before contacts.
    fn natural(&self, b: usize, sigma: f64) -> Pose {
        let (ka, kb) = (&self.keys[b - 1], &self.keys[b]);
        let yaw = ka.yaw + sigma * kb.turn;
        self.body(b, sigma, yaw, geom::lerp(ka.ground, kb.ground, sigma), 0.0)
    }

    /// Target of a hand or foot that leaves the ground in the transition into `b`, at `u`: it
    /// stays where it was until `wait`, then lifts and joins the body's interpolated shape
    /// (whose limbs are always within reach of the body, unlike a place taken from another
    /// moment of the transition).
    fn leaving_target(&self, b: usize, limb: &Limb, u: f64, wait: f64) -> Target {
        let start = self.natural(b, 0.0);
        let now = self.natural(b, geom::ease(u));
        let r = ((u - wait) / (1.0 - wait)).clamp(0.0, 1.0);
        let join = geom::ease(r / 0.75);
        // Lifted while it moves, and kept up at the end only if the body holds it up there.
        let lift = MAX_LIFT * geom::ease(r / 0.25);
        let at = |j: usize| {
            let p = geom::lerp(start[j], now[j], join);
            [p[0], p[1].max(now[j][1] + lift * (1.0 - join)), p[2]]
        };
        Target {
            end: at(limb.end),
            tip: limb.tip.map(at),
            soft: geom::ease(r / 0.25),
        }
    }

    /// Target of a moving limb at `u` of the transition into `b`: pinned between its windows;
    /// inside one, lifted first, moved across while high, set down last.
    fn moving_target(
        &self,
        b: usize,
        limb: &Limb,
        u: f64,
        [slot, of, steps]: [usize; 3],
        stepping: bool,
    ) -> Target {
        let windows = (of * steps) as f64;
        let mut from = 0.0;
        let mut active = None;
        for k in 0..steps {
            // Each step lands where the limb will be when the body has done this step's share.
            let to = geom::ease((k + 1) as f64 / steps as f64);
            let start = (k * of + slot) as f64 / windows;
            if u < start {
                break;
            }
            if u < start + 1.0 / windows {
                active = Some(((u - start) * windows, to));
                break;
            }
            from = to;
        }
        match active {
            None => {
                let p = self.natural(b, from);
                Target {
                    end: p[limb.end],
                    tip: limb.tip.map(|t| p[t]),
                    soft: 0.0,
                }
            }
            Some((r, to)) => {
                let across = self.natural(b, from + (to - from) * geom::ease((r - 0.2) / 0.6));
                let up = self.natural(b, from + (to - from) * geom::ease(r));
                let stride = dist_xz(
                    self.natural(b, from)[limb.end],
                    self.natural(b, to)[limb.end],
                );
                let lift = if stepping || stride > PLANT_TOLERANCE {
                    (0.5 * stride).clamp(MIN_LIFT, MAX_LIFT)
                } else {
                    0.0
                };
                let raise = lift * bump(r);
                let at = |j: usize| [across[j][0], up[j][1] + raise, across[j][2]];
                Target {
                    end: at(limb.end),
                    tip: limb.tip.map(at),
                    soft: bump(r),
                }
            }
        }
    }

    /// A frame of the eased transition into `b` (or of the push-off before its flight) at `u`
    /// (0–1), with the pelvis `dip` metres lower; `launch` adds the push-off's countermovement.
    fn ease_pose(&self, b: usize, u: f64, dip: f64, launch: bool) -> Pose {
        let (ka, kb, plan) = (&self.keys[b - 1], &self.keys[b], &self.plans[b]);
        let s = geom::ease(u);
        let mut targets = [None; 4];
        let (yaw, mut pose) = match kb.flight {
            Some(f) => {
                let ground = geom::lerp(ka.ground, kb.takeoff, s);
                let natural = self.body(b, s, ka.yaw, ground, 0.0);
                // u³ − u² is 0 at both ends and climbs at 1/push-off at take-off: the pelvis
                // leaves at the flight's speed after dipping below the shape's path.
                let spring = if launch {
                    f.v0 * kb.trans * (u * u * u - u * u)
                } else {
                    0.0
                };
                let mut pose = natural;
                shift_y(&mut pose, dip + spring);
                for (li, limb) in LIMBS.iter().enumerate() {
                    if plan.limbs[li] == LimbMode::PushOff {
                        let pin = |e: usize| ka.contact[e].then_some(ka.world[e]);
                        targets[li] = pinned(limb, pin(limb.end), limb.tip.and_then(pin), &pose);
                    }
                }
                (ka.yaw, pose)
            }
            None => {
                let yaw = ka.yaw + s * kb.turn;
                let mut pose = self.body(b, s, yaw, geom::lerp(ka.ground, kb.ground, s), 0.0);
                shift_y(&mut pose, dip);
                for (li, limb) in LIMBS.iter().enumerate() {
                    targets[li] = match plan.limbs[li] {
                        LimbMode::Planted => {
                            let pin = |e: usize| {
                                (ka.contact[e] && kb.contact[e])
                                    .then(|| geom::lerp(ka.world[e], kb.world[e], s))
                            };
                            pinned(limb, pin(limb.end), limb.tip.and_then(pin), &pose)
                        }
                        LimbMode::Moving { wait, .. } if wait > 0.0 => {
                            Some(self.leaving_target(b, limb, u, wait))
                        }
                        LimbMode::Moving {
                            slot,
                            of,
                            steps,
                            stepping,
                            ..
                        } => Some(self.moving_target(b, limb, u, [slot, of, steps], stepping)),
                        _ => None,
                    };
                }
                (yaw, pose)
            }
        };
        solve_on_targets(&mut pose, &targets, yaw);
        if plan.supports.is_empty() && kb.flight.is_none() {
            // A lifted hand or foot may have been what the body rested on.
            let low = lowest(&pose) - dip.max(0.0);
            if low > 0.0 {
                shift_y(&mut pose, -low);
            }
        }
        pose
    }

    /// A frame `t` seconds into the flight into `b`.
    fn flight_pose(&self, b: usize, t: f64, dip: f64, flight: Flight) -> Pose {
        let (ka, kb) = (&self.keys[b - 1], &self.keys[b]);
        let q = (t / flight.time).clamp(0.0, 1.0);
        let yaw = ka.yaw + q * kb.turn;
        let ground = geom::lerp(kb.takeoff, kb.ground, q);
        let height = kb.pelvis[1] + dip + flight.v0 * t - 0.5 * GRAVITY * t * t;
        // The feet leave the ground where they pushed off and take the landing shape in the
        // air (a jumping jack's legs open while airborne, not by sliding apart on the floor).
        let mut takeoff = inverse_kinematics(&[self.ease_pose(b, 1.0, 0.0, true)], false)[0];
        takeoff[0] = Quat::IDENTITY;
        let mix = geom::ease(q / FLIGHT_SHAPING);
        let rots: Rotations = std::array::from_fn(|j| takeoff[j].slerp(kb.rots[j], mix));
        let mut pose = world_pose(
            &rots,
            yaw,
            root_position(ground, yaw, kb.pelvis, height),
            &self.offsets,
        );
        solve_on_targets(&mut pose, &[None; 4], yaw);
        pose
    }

    /// A frame of key `k` held, with the pelvis `dip` metres lower.
    fn hold_pose(&self, k: usize, dip: f64) -> Pose {
        let key = &self.keys[k];
        let mut pose = key.world;
        shift_y(&mut pose, dip);
        let pin = |e: usize| key.contact[e].then_some(key.world[e]);
        let targets = std::array::from_fn(|li| {
            let limb = &LIMBS[li];
            pinned(limb, pin(limb.end), limb.tip.and_then(pin), &pose)
        });
        solve_on_targets(&mut pose, &targets, key.yaw);
        pose
    }

    /// The shortest duration of the transition into `b` (its push-off for a flight) that keeps
    /// every joint under [`MAX_JOINT_SPEED`]: the peak of |d position / d u| over the
    /// transition's own frames (no landing dip, no launch), divided by the speed.
    fn shortest_duration(&self, b: usize) -> f64 {
        let windows = self.plans[b]
            .limbs
            .iter()
            .map(|m| match m {
                LimbMode::Moving { of, steps, .. } => of * steps,
                _ => 1,
            })
            .max()
            .unwrap_or(1);
        let samples = 32 * windows.max(2);
        let mut prev = self.ease_pose(b, 0.0, 0.0, false);
        let mut peak = 0.0f64;
        for i in 1..=samples {
            let pose = self.ease_pose(b, i as f64 / samples as f64, 0.0, false);
            let moved = prev
                .iter()
                .zip(&pose)
                .map(|(p, q)| geom::dist(*p, *q))
                .fold(0.0, f64::max);
            peak = peak.max(moved * samples as f64);
            prev = pose;
        }
        if peak.is_finite() {
            peak * SPEED_MARGIN / MAX_JOINT_SPEED
        } else {
            0.0
        }
    }

    /// The landing dips active at `t`: the pelvis keeps its landing speed into a dip that
    /// recovers with time constant `tau` (−v₀·τ·e^(−τ/tau), deepest at v₀·tau/e).
    fn dip(&self, t: f64) -> f64 {
        let landed = self.landings.partition_point(|l| l.time <= t);
        self.landings[..landed]
            .iter()
            .rev()
            .take_while(|l| t - l.time < DIP_WINDOW)
            .map(|l| {
                let since = t - l.time;
                -l.v0 * since * (-since / l.tau).exp()
            })
            .sum()
    }

    pub(super) fn frame_at(&self, t: f64) -> Pose {
        let k = self
            .keys
            .partition_point(|k| k.reached + k.hold < t)
            .min(self.keys.len() - 1);
        let key = &self.keys[k];
        let dip = self.dip(t);
        if k > 0 && t < key.reached {
            let airborne = key.flight.map_or(0.0, |f| f.time);
            let local = (t - (key.reached - airborne - key.trans)).max(0.0);
            match key.flight {
                Some(f) if local > key.trans => {
                    self.flight_pose(k, (local - key.trans).min(f.time), dip, f)
                }
                _ => self.ease_pose(k, (local / key.trans).min(1.0), dip, true),
            }
        } else {
            self.hold_pose(k, dip)
        }
    }
}
