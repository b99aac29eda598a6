//! Pose codes and motion descriptors, turned into short English sentences per body part.
//!
//! The idea follows PoseScript (Delmas et al.): a pose is first reduced to categorical
//! "pose codes" (how bent a knee is, whether a hand is above the head, ...), and the codes are
//! then put into words. Here the codes are extended over time: a window of frames gets motion
//! descriptors (how fast and which way the body travels, how much it turns, jumps, bows, how
//! each limb moves), and those pick one short phrase per body part. The code and the wording
//! are this project's own.
//!
//! Three layers, each usable on its own:
//!
//! 1. [`frame_codes`]: categorical codes of one pose ([`FrameCodes`]).
//! 2. [`describe_window`]: numbers and categories for a slice of frames at 20 fps
//!    ([`MotionDescriptor`]).
//! 3. [`part_sentences`] and [`describe_motion`]: the sentences that caption training clips
//!    (one per body part) and describe generated motion for a reviewer (whole body).
//!
//! Everything is deterministic. Poses are world positions of the 22 SMPL joints in metres, Y up;
//! directions such as "in front" or "to the left" are judged in the body frame of each frame
//! (see [`facing`]), so they do not depend on where the character faces in the world.

mod body;
mod frame;
mod motion;
mod text;

#[cfg(test)]
mod tests;

pub use body::{
    angle_from_vertical_deg, body_level, relative_offset, torso_in_hip_frame, torso_lean,
    torso_twist, torso_twist_deg, BodyPoint, Lean, Limb, PelvisLevel, Relation, Support, Twist,
    CROUCH_PELVIS_M, HAND_CONTACT_M, LYING_MIN_DEG, LYING_PELVIS_M, PELVIS_CONTACT_M,
    PLANK_PELVIS_M, TWIST_MIN_DEG, UPRIGHT_MAX_DEG,
};
pub use frame::{
    facing, floor_height, frame_codes, joint_angle_deg, ArmCodes, Bend, Depth, Distance,
    FrameCodes, LegCodes, Orientation, Side, Vertical, CLOSE_MAX_M, DEPTH_BAND_M, FOOT_CONTACT_M,
    HEIGHT_BAND_M, HORIZONTAL_MIN_DEG, KNEE_CONTACT_M, MIDLINE_BAND_M, PARTIALLY_BENT_MIN_DEG,
    SHOULDER_WIDTH_MAX_M, SLIGHTLY_BENT_MIN_DEG, SPREAD_MAX_M, STRAIGHT_MIN_DEG, VERTICAL_MAX_DEG,
};
pub use motion::{
    describe_window, describe_window_with_floor, ArmHeight, ArmMotion, LegDirection, LegMotion,
    Level, MotionDescriptor, Pace, Reach, Torso, Travel, ACTIVE_MIN_MPS, BOW_MIN_DEG, CROSS_MIN_M,
    JUMP_CLEARANCE_M, JUMP_MAX_FRAMES, JUMP_MIN_FRAMES, JUMP_PEAK_CLEARANCE_M, JUMP_RISE_M,
    KICK_MIN_MPS, KNEE_LIFT_BELOW_HIP_M, LEAN_BACK_DEG, LEVEL_CHANGE_RATIO, LIFT_CLEARANCE_M,
    LIFT_REACH_M, LOW_PELVIS_RATIO, NEAR_HEAD_M, REACH_MIN_M, RUN_MIN_MPS, STILL_MAX_MPS,
    SWING_MIN_REVERSALS, SWING_REVERSAL_M, TILT_CHANGE_DEG, WALK_MIN_MPS, WAVE_MIN_REVERSALS,
    WAVE_REVERSAL_M,
};
pub use text::{describe_motion, part_sentences, TURN_MIN_DEG, WINDOW_FRAMES};
