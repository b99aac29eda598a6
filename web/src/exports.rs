//! The page's downloads, as bytes: BVH (our 22-joint skeleton at 20 fps, importable by
//! Blender), glTF binary (the shaded figure skinned on that skeleton, with the motion as its
//! animation), JSON (joints per frame with the prompt and the plan) and NPY (HumanML3D's 263
//! features, or the (T, 22, 3) joints).

use crate::take::Take;
use coma::features::{features_to_npy, joints_to_npy};
use coma::skeleton::Pose;
use coma::timing::FPS;

/// The export formats.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Format {
    Bvh,
    Glb,
    Json,
    FeaturesNpy,
    JointsNpy,
}

impl Format {
    pub const ALL: [Format; 5] = [
        Format::Bvh,
        Format::Glb,
        Format::Json,
        Format::FeaturesNpy,
        Format::JointsNpy,
    ];

    /// The button's label.
    pub fn label(self) -> &'static str {
        match self {
            Format::Bvh => "BVH",
            Format::Glb => "glTF (.glb)",
            Format::Json => "JSON",
            Format::FeaturesNpy => "NPY (features)",
            Format::JointsNpy => "NPY (joints)",
        }
    }

    /// File name of a download.
    pub fn file_name(self) -> &'static str {
        match self {
            Format::Bvh => "motion.bvh",
            Format::Glb => "motion.glb",
            Format::Json => "motion.json",
            Format::FeaturesNpy => "motion-features.npy",
            Format::JointsNpy => "motion-joints.npy",
        }
    }

    /// MIME type of a download.
    pub fn mime(self) -> &'static str {
        match self {
            Format::Bvh => "text/plain",
            Format::Glb => "model/gltf-binary",
            Format::Json => "application/json",
            _ => "application/octet-stream",
        }
    }
}

fn poses(take: &Take) -> Vec<Pose> {
    take.motion
        .joints
        .iter()
        .map(|p| p.map(|j| j.map(|v| v as f64)))
        .collect()
}

/// The bytes of `take` in `format`.
pub fn export(take: &Take, format: Format) -> Result<Vec<u8>, String> {
    match format {
        Format::Bvh => coma::bvh::writer::write_bvh(&poses(take), FPS)
            .map(String::into_bytes)
            .map_err(|e| format!("cannot write BVH: {e}")),
        Format::Glb => coma::gltf::write_glb(&poses(take), FPS, coma::gltf::JointNames::Smpl)
            .map_err(|e| format!("cannot write glTF: {e}")),
        Format::Json => {
            let mut json = coma::motion_file::joints_to_json(&poses(take));
            json["prompt"] = take.prompt.clone().into();
            json["seed"] = take.seed.into();
            json["plan"] = serde_json::to_value(&take.plan).unwrap_or(serde_json::Value::Null);
            // Where each segment lies in the frames, which the plan itself (in seconds)
            // does not say exactly.
            json["segments"] = take
                .segments
                .iter()
                .map(|s| serde_json::json!({"text": s.text, "from": s.from, "to": s.to}))
                .collect();
            Ok(json.to_string().into_bytes())
        }
        Format::FeaturesNpy => Ok(features_to_npy(&take.motion.features).to_bytes_f32()),
        Format::JointsNpy => Ok(joints_to_npy(&poses(take)).to_bytes_f32()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::take::plan_from_link;
    use coma::features::FEATURE_DIM;
    use coma::session::Motion;
    use coma::share::LinkPlan;

    fn take() -> Take {
        // A standing pose from the reference skeleton, swaying.
        let offsets = coma::skeleton::Offsets::reference().0;
        let mut rest = [[0.0f64; 3]; 22];
        for j in 1..22 {
            let p = coma::skeleton::PARENTS[j].unwrap();
            rest[j] = std::array::from_fn(|k| rest[p][k] + offsets[j][k]);
        }
        let joints: Vec<[[f32; 3]; 22]> = (0..10)
            .map(|t| {
                rest.map(|j| {
                    [
                        j[0] as f32 + t as f32 * 0.01,
                        j[1] as f32 + 0.9,
                        j[2] as f32,
                    ]
                })
            })
            .collect();
        Take::new(
            Motion {
                tokens: coma::model::tokens::MotionTokens::new(vec![vec![vec![1, 2]; 4]; 4])
                    .unwrap(),
                features: vec![[0.5; FEATURE_DIM]; 9],
                joints,
            },
            "a person sways".into(),
            3,
            vec![],
            None,
            plan_from_link(&LinkPlan::None, "a person sways", 10).1,
        )
    }

    #[test]
    fn exports_read_back_with_our_readers() {
        let t = take();
        let bvh = String::from_utf8(export(&t, Format::Bvh).unwrap()).unwrap();
        let parsed = coma::bvh::Bvh::parse(&bvh).unwrap();
        assert_eq!(parsed.frames.len(), 10);
        let glb = export(&t, Format::Glb).unwrap();
        assert_eq!(&glb[..4], b"glTF");
        assert_eq!(
            u32::from_le_bytes(glb[8..12].try_into().unwrap()) as usize,
            glb.len()
        );
        let json: serde_json::Value =
            serde_json::from_slice(&export(&t, Format::Json).unwrap()).unwrap();
        assert_eq!(json["frames"].as_array().unwrap().len(), 10);
        assert_eq!(json["prompt"], "a person sways");
        // A take without the planner's plan has its segments only.
        assert_eq!(json["plan"], serde_json::Value::Null);
        assert_eq!(json["segments"][0]["to"], 10);
        // A planned take exports the planner's whole plan.
        let mut planned = t.clone();
        planned.plan = Some(coma::agents::planner::offline::plan("a person bows", None));
        let json: serde_json::Value =
            serde_json::from_slice(&export(&planned, Format::Json).unwrap()).unwrap();
        assert_eq!(json["plan"]["segments"][0]["base"], "a person bows");
        let f = coma::npy::NpyArray::from_bytes(&export(&t, Format::FeaturesNpy).unwrap()).unwrap();
        assert_eq!(f.shape, vec![9, FEATURE_DIM]);
        let j = coma::npy::NpyArray::from_bytes(&export(&t, Format::JointsNpy).unwrap()).unwrap();
        assert_eq!(j.shape, vec![10, 22, 3]);
    }
}
