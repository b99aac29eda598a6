//! Writes a 22-joint motion as a binary glTF 2.0 file (`.glb`): the body ([`crate::figure`])
//! as a skinned mesh on a skeleton of 22 joint nodes, and the motion as one animation.
//!
//! The file:
//! - metres, Y up, facing +Z (glTF's own conventions match the product's);
//! - nodes 0..22 are the joints in [`JOINT_NAMES`] order (lower case SMPL names, as the BVH
//!   export names them) or, with [`JointNames::Mixamo`], Mixamo's rig names
//!   ([`MIXAMO_NAMES`], e.g. `mixamorig:Hips`) so retargeting tools map them; each joint's
//!   translation is its rest offset from its parent, its rest rotation the identity; node 22
//!   is the mesh; the scene holds nodes 0 and 22;
//! - the skeleton and the rotations are the BVH export's ([`Rig`]): legs and arms hanging
//!   down, head up, rotations solved from the joint positions, so the joint nodes' world
//!   positions reproduce the motion's joints (exactly when its bones keep their lengths, as
//!   [`crate::skeleton::fixed_bones`] makes them);
//! - the mesh is the figure in the rest pose, every vertex weighted 1.0 to its joint, with
//!   inverse bind matrices that undo each joint's rest translation;
//! - one animation, "motion": the pelvis's translation and every joint's rotation, one key
//!   per frame at the motion's frame rate, LINEAR (quaternions kept in one hemisphere from
//!   frame to frame so the slerp between keys takes the short way).
//!
//! Hand-written rather than with a glTF crate: the container is two chunks and the JSON is a
//! dozen small objects, which `serde_json` writes; a crate would add a dependency to the
//! page's wasm for that.

use crate::bvh::writer::{children, Rig};
use crate::figure::figure_mesh;
use crate::geom::Quat;
use crate::skeleton::{Pose, JOINT_NAMES, NUM_JOINTS, PARENTS};
use serde_json::{json, Value};

/// Joint names in index order as Mixamo's rig calls them (the 22 body joints; Mixamo's
/// extra spine, finger and head-top bones have no counterpart).
pub const MIXAMO_NAMES: [&str; NUM_JOINTS] = [
    "mixamorig:Hips",
    "mixamorig:LeftUpLeg",
    "mixamorig:RightUpLeg",
    "mixamorig:Spine",
    "mixamorig:LeftLeg",
    "mixamorig:RightLeg",
    "mixamorig:Spine1",
    "mixamorig:LeftFoot",
    "mixamorig:RightFoot",
    "mixamorig:Spine2",
    "mixamorig:LeftToeBase",
    "mixamorig:RightToeBase",
    "mixamorig:Neck",
    "mixamorig:LeftShoulder",
    "mixamorig:RightShoulder",
    "mixamorig:Head",
    "mixamorig:LeftArm",
    "mixamorig:RightArm",
    "mixamorig:LeftForeArm",
    "mixamorig:RightForeArm",
    "mixamorig:LeftHand",
    "mixamorig:RightHand",
];

/// How the joint nodes are named.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum JointNames {
    /// [`JOINT_NAMES`]: `pelvis`, `l_hip`, … (the BVH export's).
    #[default]
    Smpl,
    /// [`MIXAMO_NAMES`]: `mixamorig:Hips`, `mixamorig:LeftUpLeg`, …
    Mixamo,
}

impl JointNames {
    /// The 22 names in joint order.
    pub fn names(self) -> &'static [&'static str; NUM_JOINTS] {
        match self {
            JointNames::Smpl => &JOINT_NAMES,
            JointNames::Mixamo => &MIXAMO_NAMES,
        }
    }
}

/// Why a motion cannot be written.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum GltfError {
    #[error("the motion has no frames")]
    Empty,
    #[error("frame {0} has a non-finite joint position")]
    NonFinite(usize),
    #[error("the frame rate must be positive, got {0}")]
    FrameRate(f64),
}

/// glTF's component types and buffer-view targets.
const FLOAT: u32 = 5126;
const UNSIGNED_BYTE: u32 = 5121;
const UNSIGNED_INT: u32 = 5125;
const ARRAY_BUFFER: u32 = 34962;
const ELEMENT_ARRAY_BUFFER: u32 = 34963;
/// GLB chunk types: "JSON" and "BIN\0" read as little-endian u32.
const CHUNK_JSON: u32 = 0x4E4F_534A;
const CHUNK_BIN: u32 = 0x004E_4942;
const GLB_MAGIC: u32 = 0x4654_6C67;

/// The binary buffer being laid out, with its buffer views and accessors.
#[derive(Default)]
struct Buffer {
    bytes: Vec<u8>,
    views: Vec<Value>,
    accessors: Vec<Value>,
}

impl Buffer {
    /// Appends one buffer view of `bytes` (4-byte aligned, as every accessor here needs) and
    /// an accessor over it; returns the accessor's index.
    fn push(&mut self, bytes: &[u8], target: Option<u32>, mut accessor: Value) -> usize {
        while self.bytes.len() % 4 != 0 {
            self.bytes.push(0);
        }
        let mut view =
            json!({"buffer": 0, "byteOffset": self.bytes.len(), "byteLength": bytes.len()});
        if let Some(t) = target {
            view["target"] = t.into();
        }
        self.bytes.extend_from_slice(bytes);
        accessor["bufferView"] = self.views.len().into();
        self.views.push(view);
        self.accessors.push(accessor);
        self.accessors.len() - 1
    }

    /// Floats, `width` per element (glTF type `kind`); `bounds` adds the per-component
    /// min and max (required on positions and animation inputs).
    fn floats(
        &mut self,
        values: &[f32],
        width: usize,
        kind: &str,
        target: Option<u32>,
        bounds: bool,
    ) -> usize {
        let mut accessor =
            json!({"componentType": FLOAT, "count": values.len() / width, "type": kind});
        if bounds {
            let mut lo = vec![f32::INFINITY; width];
            let mut hi = vec![f32::NEG_INFINITY; width];
            for row in values.chunks(width) {
                for (i, &v) in row.iter().enumerate() {
                    lo[i] = lo[i].min(v);
                    hi[i] = hi[i].max(v);
                }
            }
            accessor["min"] = json!(lo);
            accessor["max"] = json!(hi);
        }
        let bytes: Vec<u8> = values.iter().flat_map(|v| v.to_le_bytes()).collect();
        self.push(&bytes, target, accessor)
    }
}

/// A quaternion as glTF stores it: `(x, y, z, w)`.
fn xyzw(q: Quat) -> [f32; 4] {
    let [w, x, y, z] = q.0;
    [x as f32, y as f32, z as f32, w as f32]
}

/// The motion as `.glb` bytes: `poses` are the joints of each frame in metres (Y up), `fps`
/// the frame rate (20 for our motions), `names` how the joint nodes are named.
pub fn write_glb(poses: &[Pose], fps: f64, names: JointNames) -> Result<Vec<u8>, GltfError> {
    if poses.is_empty() {
        return Err(GltfError::Empty);
    }
    if !(fps.is_finite() && fps > 0.0) {
        return Err(GltfError::FrameRate(fps));
    }
    if let Some(t) = poses
        .iter()
        .position(|p| p.iter().flatten().any(|v| !v.is_finite()))
    {
        return Err(GltfError::NonFinite(t));
    }
    let rig = Rig::fit(poses);
    // The bind pose stands where the motion starts.
    let rest = rig.rest_pose(poses[0][0]);
    let mut buffer = Buffer::default();

    // The figure in the rest pose, each vertex on its joint with weight 1.
    let mesh = figure_mesh(&rest.map(|j| j.map(|v| v as f32)));
    let flat = |v: &[[f32; 3]]| v.iter().flatten().copied().collect::<Vec<f32>>();
    let position = buffer.floats(&flat(&mesh.positions), 3, "VEC3", Some(ARRAY_BUFFER), true);
    let normal = buffer.floats(&flat(&mesh.normals), 3, "VEC3", Some(ARRAY_BUFFER), false);
    let joint_bytes: Vec<u8> = mesh.joints.iter().flat_map(|&j| [j, 0, 0, 0]).collect();
    let joints = buffer.push(
        &joint_bytes,
        Some(ARRAY_BUFFER),
        json!({"componentType": UNSIGNED_BYTE, "count": mesh.joints.len(), "type": "VEC4"}),
    );
    let weight_values: Vec<f32> = mesh
        .joints
        .iter()
        .flat_map(|_| [1.0, 0.0, 0.0, 0.0])
        .collect();
    let weights = buffer.floats(&weight_values, 4, "VEC4", Some(ARRAY_BUFFER), false);
    let index_bytes: Vec<u8> = mesh.indices.iter().flat_map(|i| i.to_le_bytes()).collect();
    let indices = buffer.push(
        &index_bytes,
        Some(ELEMENT_ARRAY_BUFFER),
        json!({"componentType": UNSIGNED_INT, "count": mesh.indices.len(), "type": "SCALAR"}),
    );
    // Inverse bind matrices (column-major): every joint's rest rotation is the identity, so
    // each undoes its rest translation only.
    let ibm: Vec<f32> = rest
        .iter()
        .flat_map(|p| {
            let [x, y, z] = p.map(|v| -v as f32);
            [
                1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, x, y, z, 1.0,
            ]
        })
        .collect();
    let inverse_bind = buffer.floats(&ibm, 16, "MAT4", None, false);

    // The animation: key times, the root's path, every joint's rotation.
    let times: Vec<f32> = (0..poses.len()).map(|t| (t as f64 / fps) as f32).collect();
    let input = buffer.floats(&times, 1, "SCALAR", None, true);
    let root: Vec<f32> = poses.iter().flat_map(|p| p[0].map(|v| v as f32)).collect();
    let mut samplers = vec![
        json!({"input": input, "output": buffer.floats(&root, 3, "VEC3", None, false), "interpolation": "LINEAR"}),
    ];
    let mut channels = vec![json!({"sampler": 0, "target": {"node": 0, "path": "translation"}})];
    let locals: Vec<_> = poses.iter().map(|p| rig.local_rotations(p)).collect();
    for j in 0..NUM_JOINTS {
        let mut previous = Quat::IDENTITY;
        let rotations: Vec<f32> = locals
            .iter()
            .flat_map(|local| {
                let mut q = local[j];
                if q.0.iter().zip(previous.0).map(|(a, b)| a * b).sum::<f64>() < 0.0 {
                    q = Quat(q.0.map(|v| -v));
                }
                previous = q;
                xyzw(q)
            })
            .collect();
        channels
            .push(json!({"sampler": samplers.len(), "target": {"node": j, "path": "rotation"}}));
        samplers.push(json!({"input": input, "output": buffer.floats(&rotations, 4, "VEC4", None, false), "interpolation": "LINEAR"}));
    }

    let names = names.names();
    let mut nodes: Vec<Value> = (0..NUM_JOINTS)
        .map(|j| {
            let t = match PARENTS[j] {
                None => rest[0],
                Some(_) => rig.offsets[j],
            };
            let mut node = json!({"name": names[j], "translation": t});
            let kids = children(j);
            if !kids.is_empty() {
                node["children"] = json!(kids);
            }
            node
        })
        .collect();
    nodes.push(json!({"name": "body", "mesh": 0, "skin": 0}));
    let document = json!({
        "asset": {"version": "2.0", "generator": "CoMA in the browser (coma::gltf)"},
        "scene": 0,
        "scenes": [{"name": "motion", "nodes": [0, NUM_JOINTS]}],
        "nodes": nodes,
        "meshes": [{"name": "body", "primitives": [{
            "attributes": {"POSITION": position, "NORMAL": normal, "JOINTS_0": joints, "WEIGHTS_0": weights},
            "indices": indices,
            "material": 0,
            "mode": 4,
        }]}],
        "materials": [{"name": "body", "pbrMetallicRoughness": {
            "baseColorFactor": [0.8, 0.72, 0.64, 1.0], "metallicFactor": 0.0, "roughnessFactor": 0.7,
        }}],
        "skins": [{"name": "skeleton", "inverseBindMatrices": inverse_bind, "joints": (0..NUM_JOINTS).collect::<Vec<_>>(), "skeleton": 0}],
        "animations": [{"name": "motion", "samplers": samplers, "channels": channels}],
        "buffers": [{"byteLength": buffer.bytes.len()}],
        "bufferViews": buffer.views,
        "accessors": buffer.accessors,
    });
    Ok(glb_container(&document.to_string(), buffer.bytes))
}

/// The GLB container: a 12-byte header, the JSON chunk padded with spaces and the binary
/// chunk padded with zeros, each to 4 bytes.
fn glb_container(json: &str, mut bin: Vec<u8>) -> Vec<u8> {
    let mut json = json.as_bytes().to_vec();
    while json.len() % 4 != 0 {
        json.push(b' ');
    }
    while bin.len() % 4 != 0 {
        bin.push(0);
    }
    let total = 12 + 8 + json.len() + 8 + bin.len();
    let mut out = Vec::with_capacity(total);
    for word in [GLB_MAGIC, 2, total as u32, json.len() as u32, CHUNK_JSON] {
        out.extend_from_slice(&word.to_le_bytes());
    }
    out.extend_from_slice(&json);
    for word in [bin.len() as u32, CHUNK_BIN] {
        out.extend_from_slice(&word.to_le_bytes());
    }
    out.extend_from_slice(&bin);
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::{self, Vec3};
    use crate::skeleton::{self, forward_kinematics, joint, Offsets, Rotations};

    /// A parsed GLB: its JSON and binary chunk, with every structural check of the container
    /// and the accessors done on the way.
    struct Glb {
        json: Value,
        bin: Vec<u8>,
    }

    fn u32_at(bytes: &[u8], at: usize) -> u32 {
        u32::from_le_bytes(bytes[at..at + 4].try_into().unwrap())
    }

    impl Glb {
        fn parse(bytes: &[u8]) -> Glb {
            assert_eq!(u32_at(bytes, 0), GLB_MAGIC, "magic");
            assert_eq!(u32_at(bytes, 4), 2, "version");
            assert_eq!(u32_at(bytes, 8) as usize, bytes.len(), "total length");
            let json_len = u32_at(bytes, 12) as usize;
            assert_eq!(u32_at(bytes, 16), CHUNK_JSON);
            assert_eq!(json_len % 4, 0, "JSON chunk aligned");
            let json: Value = serde_json::from_slice(&bytes[20..20 + json_len]).unwrap();
            let at = 20 + json_len;
            let bin_len = u32_at(bytes, at) as usize;
            assert_eq!(u32_at(bytes, at + 4), CHUNK_BIN);
            assert_eq!(bin_len % 4, 0, "BIN chunk aligned");
            assert_eq!(at + 8 + bin_len, bytes.len(), "nothing after the BIN chunk");
            let bin = bytes[at + 8..].to_vec();
            assert!(json["buffers"][0]["byteLength"].as_u64().unwrap() as usize <= bin.len());
            let glb = Glb { json, bin };
            glb.check_accessors();
            glb
        }

        fn count(&self, accessor: usize) -> usize {
            self.json["accessors"][accessor]["count"].as_u64().unwrap() as usize
        }

        /// Every accessor lies inside its buffer view, every view inside the buffer, aligned
        /// to its component size; declared min/max match the data.
        fn check_accessors(&self) {
            let buffer_len = self.json["buffers"][0]["byteLength"].as_u64().unwrap() as usize;
            for view in self.json["bufferViews"].as_array().unwrap() {
                let offset = view["byteOffset"].as_u64().unwrap() as usize;
                let len = view["byteLength"].as_u64().unwrap() as usize;
                assert!(offset + len <= buffer_len, "view out of the buffer");
                assert_eq!(offset % 4, 0);
            }
            for (i, a) in self.json["accessors"]
                .as_array()
                .unwrap()
                .iter()
                .enumerate()
            {
                let view = &self.json["bufferViews"][a["bufferView"].as_u64().unwrap() as usize];
                let width = width(a["type"].as_str().unwrap());
                let size = match a["componentType"].as_u64().unwrap() as u32 {
                    FLOAT | UNSIGNED_INT => 4,
                    UNSIGNED_BYTE => 1,
                    other => panic!("component type {other}"),
                };
                let len = view["byteLength"].as_u64().unwrap() as usize;
                assert_eq!(len, self.count(i) * width * size, "accessor {i} length");
                if a.get("min").is_some() {
                    let values = self.floats(i);
                    for c in 0..width {
                        let column = values.iter().skip(c).step_by(width);
                        let lo = column.clone().fold(f32::INFINITY, |m, &v| m.min(v));
                        let hi = column.fold(f32::NEG_INFINITY, |m, &v| m.max(v));
                        assert_eq!(a["min"][c].as_f64().unwrap() as f32, lo);
                        assert_eq!(a["max"][c].as_f64().unwrap() as f32, hi);
                    }
                }
            }
        }

        fn bytes(&self, accessor: usize) -> &[u8] {
            let a = &self.json["accessors"][accessor];
            let view = &self.json["bufferViews"][a["bufferView"].as_u64().unwrap() as usize];
            let offset = view["byteOffset"].as_u64().unwrap() as usize;
            &self.bin[offset..offset + view["byteLength"].as_u64().unwrap() as usize]
        }

        fn floats(&self, accessor: usize) -> Vec<f32> {
            assert_eq!(
                self.json["accessors"][accessor]["componentType"],
                json!(FLOAT)
            );
            self.bytes(accessor)
                .chunks(4)
                .map(|b| f32::from_le_bytes(b.try_into().unwrap()))
                .collect()
        }

        /// The sampler output of `path` on `node`, one row per key.
        fn channel(&self, node: usize, path: &str) -> Vec<Vec<f64>> {
            let animation = &self.json["animations"][0];
            let channel = animation["channels"]
                .as_array()
                .unwrap()
                .iter()
                .find(|c| c["target"]["node"] == json!(node) && c["target"]["path"] == path)
                .unwrap_or_else(|| panic!("no {path} channel on node {node}"));
            let sampler = &animation["samplers"][channel["sampler"].as_u64().unwrap() as usize];
            assert_eq!(sampler["interpolation"], "LINEAR");
            let output = sampler["output"].as_u64().unwrap() as usize;
            let width = width(self.json["accessors"][output]["type"].as_str().unwrap());
            self.floats(output)
                .chunks(width)
                .map(|r| r.iter().map(|&v| v as f64).collect())
                .collect()
        }

        /// World positions of the joint nodes at key `t`, walking the node hierarchy from
        /// the scene's root with the animation's keys (nodes without a channel keep their
        /// own transform).
        fn joints_at(&self, t: usize) -> Pose {
            let mut out = [[0.0; 3]; NUM_JOINTS];
            let root = self.json["scenes"][0]["nodes"][0].as_u64().unwrap() as usize;
            self.walk(root, t, [0.0; 3], Quat::IDENTITY, &mut out);
            out
        }

        fn walk(&self, node: usize, t: usize, at: Vec3, turn: Quat, out: &mut Pose) {
            let n = &self.json["nodes"][node];
            let translation = self.animated(node, "translation", t).map_or_else(
                || {
                    let v = n["translation"].as_array().unwrap();
                    [0, 1, 2].map(|i| v[i].as_f64().unwrap())
                },
                |v| [v[0], v[1], v[2]],
            );
            let rotation = self
                .animated(node, "rotation", t)
                .map_or(Quat::IDENTITY, |q| Quat([q[3], q[0], q[1], q[2]]));
            let position = geom::add(at, turn.rotate(translation));
            let turn = turn.mul(rotation);
            out[node] = position;
            for child in n["children"].as_array().into_iter().flatten() {
                self.walk(child.as_u64().unwrap() as usize, t, position, turn, out);
            }
        }

        fn animated(&self, node: usize, path: &str, t: usize) -> Option<Vec<f64>> {
            let any = self.json["animations"][0]["channels"]
                .as_array()
                .unwrap()
                .iter()
                .any(|c| c["target"]["node"] == json!(node) && c["target"]["path"] == path);
            any.then(|| self.channel(node, path)[t].clone())
        }
    }

    fn width(kind: &str) -> usize {
        match kind {
            "SCALAR" => 1,
            "VEC3" => 3,
            "VEC4" => 4,
            "MAT4" => 16,
            other => panic!("type {other}"),
        }
    }

    /// A motion on the reference skeleton whose hips and collars stay rigid: walking in a
    /// turn, knees and elbows bending, the head nodding.
    fn synthetic_motion(frames: usize) -> Vec<Pose> {
        let mut offsets = Offsets::reference();
        offsets.0[joint::HEAD] = [0.0, 0.1, 0.02];
        let rotations: Vec<Rotations> = (0..frames)
            .map(|t| {
                let s = (t as f64 * 0.3).sin();
                let mut r = [Quat::IDENTITY; NUM_JOINTS];
                r[0] = Quat::from_yaw(0.04 * t as f64)
                    .mul(Quat::from_axis_angle([1.0, 0.0, 0.0], 0.1 * s));
                r[joint::L_HIP] = Quat::from_axis_angle([1.0, 0.0, 0.0], 0.5 * s);
                r[joint::R_HIP] = Quat::from_axis_angle([1.0, 0.0, 0.0], -0.5 * s);
                r[joint::L_KNEE] = Quat::from_axis_angle([1.0, 0.0, 0.0], 0.6 + 0.5 * s);
                r[joint::L_SHOULDER] = Quat::from_axis_angle([0.0, 0.3, 1.0], 1.2 + s);
                r[joint::R_ELBOW] = Quat::from_axis_angle([1.0, 0.2, 0.0], -1.4 * s);
                r[joint::NECK] = Quat::from_axis_angle([1.0, 0.0, 0.0], 0.3 * s);
                r
            })
            .collect();
        let root: Vec<Vec3> = (0..frames)
            .map(|t| {
                [
                    0.01 * t as f64,
                    0.92 + 0.02 * (t as f64).cos(),
                    0.05 * t as f64,
                ]
            })
            .collect();
        forward_kinematics(&rotations, &offsets, &root)
    }

    /// A motion from real HumanML3D features, on the product's skeleton as the engine
    /// returns motions.
    fn reference_motion() -> Option<Vec<Pose>> {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../../shared/data/humanml3d-reference/new_joint_vecs/012314.npy");
        if !path.exists() {
            eprintln!("skipped: {} is missing", path.display());
            return None;
        }
        let array = crate::npy::NpyArray::read(&path).unwrap();
        let features = crate::features::features_from_npy(&array).unwrap();
        Some(skeleton::fixed_bones(&crate::features::features_to_joints(
            &features,
        )))
    }

    /// Writes `poses`, reads the file back and re-evaluates the joints at every frame.
    fn round_trip(poses: &[Pose], names: JointNames) -> (Glb, f64) {
        let bytes = write_glb(poses, 20.0, names).unwrap();
        let glb = Glb::parse(&bytes);
        let input = glb.json["animations"][0]["samplers"][0]["input"]
            .as_u64()
            .unwrap() as usize;
        assert_eq!(glb.count(input), poses.len());
        let times = glb.floats(input);
        assert!((times[times.len() - 1] as f64 - (poses.len() - 1) as f64 / 20.0).abs() < 1e-6);
        let mut worst = 0.0f64;
        for (t, pose) in poses.iter().enumerate() {
            let back = glb.joints_at(t);
            worst = worst.max(skeleton::max_joint_distance(&[back], &[*pose]));
        }
        (glb, worst)
    }

    #[test]
    fn synthetic_motion_round_trips() {
        let poses = synthetic_motion(60);
        let (glb, worst) = round_trip(&poses, JointNames::Smpl);
        assert!(worst < 1e-4, "worst joint error {worst} m");
        let names: Vec<_> = glb.json["nodes"].as_array().unwrap()[..NUM_JOINTS]
            .iter()
            .map(|n| n["name"].as_str().unwrap().to_string())
            .collect();
        assert_eq!(names, JOINT_NAMES);
        // 22 rotation channels and the root's translation, one key per frame.
        let channels = glb.json["animations"][0]["channels"].as_array().unwrap();
        assert_eq!(channels.len(), NUM_JOINTS + 1);
        for j in 0..NUM_JOINTS {
            let keys = glb.channel(j, "rotation");
            assert_eq!(keys.len(), 60);
            for pair in keys.windows(2) {
                let d: f64 = pair[0].iter().zip(&pair[1]).map(|(a, b)| a * b).sum();
                assert!(
                    d >= 0.0,
                    "joint {j}: consecutive keys in opposite hemispheres"
                );
            }
        }
    }

    #[test]
    fn motion_from_features_round_trips() {
        let Some(poses) = reference_motion() else {
            return;
        };
        let (glb, worst) = round_trip(&poses, JointNames::Mixamo);
        assert!(worst < 1e-4, "worst joint error {worst} m");
        assert_eq!(glb.json["nodes"][0]["name"], "mixamorig:Hips");
        assert_eq!(
            glb.json["nodes"][joint::L_KNEE]["name"],
            "mixamorig:LeftLeg"
        );
        assert_eq!(
            glb.json["nodes"][joint::R_WRIST]["name"],
            "mixamorig:RightHand"
        );
    }

    #[test]
    fn skin_carries_the_figure_with_its_bones() {
        let poses = synthetic_motion(30);
        let glb = Glb::parse(&write_glb(&poses, 20.0, JointNames::Smpl).unwrap());
        let primitive = &glb.json["meshes"][0]["primitives"][0];
        let attr = |name: &str| primitive["attributes"][name].as_u64().unwrap() as usize;
        let positions = glb.floats(attr("POSITION"));
        let joints = glb.bytes(attr("JOINTS_0")).to_vec();
        let weights = glb.floats(attr("WEIGHTS_0"));
        let vertices = glb.count(attr("POSITION"));
        assert_eq!(glb.count(attr("NORMAL")), vertices);
        assert_eq!(glb.count(attr("JOINTS_0")), vertices);
        let indices = primitive["indices"].as_u64().unwrap() as usize;
        assert_eq!(
            glb.json["accessors"][indices]["componentType"],
            json!(UNSIGNED_INT)
        );
        assert!(glb
            .bytes(indices)
            .chunks(4)
            .all(|b| (u32::from_le_bytes(b.try_into().unwrap()) as usize) < vertices));
        assert!(weights.chunks(4).all(|w| w == [1.0, 0.0, 0.0, 0.0]));
        // Inverse bind matrices: translations only, undoing the rest pose's joints.
        let skin = &glb.json["skins"][0];
        let ibm = glb.floats(skin["inverseBindMatrices"].as_u64().unwrap() as usize);
        let rest = glb.rest_joints();
        for j in 0..NUM_JOINTS {
            let m = &ibm[j * 16..j * 16 + 16];
            for k in 0..3 {
                assert!((m[12 + k] as f64 + rest[j][k]).abs() < 1e-6);
            }
        }
        // Skinned at every frame, a vertex keeps its place along its bone: its distance
        // along the bone from the joint is the same as in the rest pose.
        let inverse_bind = |j: usize, p: Vec3| geom::sub(p, rest[j]);
        for t in [0, 11, 29] {
            let posed = glb.joints_at(t);
            let turns = glb.world_rotations(t);
            for v in 0..vertices {
                let j = joints[v * 4] as usize;
                let kids = children(j);
                let [c] = kids.as_slice() else { continue };
                let p: Vec3 = std::array::from_fn(|k| positions[v * 3 + k] as f64);
                let skinned = geom::add(posed[j], turns[j].rotate(inverse_bind(j, p)));
                let along = |x: Vec3, a: Vec3, b: Vec3| {
                    geom::dot(geom::sub(x, a), geom::normalize(geom::sub(b, a)))
                };
                let before = along(p, rest[j], rest[*c]);
                let after = along(skinned, posed[j], posed[*c]);
                assert!(
                    (before - after).abs() < 1e-4,
                    "vertex {v} slid along bone {j}"
                );
                // And as far from the bone's line.
                let off = |x: Vec3, a: Vec3, s: f64| {
                    let d = geom::sub(x, a);
                    (geom::dot(d, d) - s * s).max(0.0).sqrt()
                };
                assert!((off(p, rest[j], before) - off(skinned, posed[j], after)).abs() < 1e-3);
            }
        }
    }

    impl Glb {
        /// The joints' world positions with every node at its own (rest) transform.
        fn rest_joints(&self) -> Pose {
            let mut out = [[0.0; 3]; NUM_JOINTS];
            for j in 0..NUM_JOINTS {
                let v = self.json["nodes"][j]["translation"].as_array().unwrap();
                let t = [0, 1, 2].map(|i| v[i].as_f64().unwrap());
                out[j] = match PARENTS[j] {
                    None => t,
                    Some(p) => geom::add(out[p], t),
                };
            }
            out
        }

        /// The joints' world rotations at key `t`.
        fn world_rotations(&self, t: usize) -> [Quat; NUM_JOINTS] {
            let mut out = [Quat::IDENTITY; NUM_JOINTS];
            for j in 0..NUM_JOINTS {
                let q = self.channel(j, "rotation")[t].clone();
                let local = Quat([q[3], q[0], q[1], q[2]]);
                out[j] = match PARENTS[j] {
                    None => local,
                    Some(p) => out[p].mul(local),
                };
            }
            out
        }
    }

    #[test]
    fn one_frame_and_bad_input() {
        let poses = synthetic_motion(1);
        let (_, worst) = round_trip(&poses, JointNames::Smpl);
        assert!(worst < 1e-4);
        assert_eq!(
            write_glb(&[], 20.0, JointNames::Smpl),
            Err(GltfError::Empty)
        );
        let mut bad = synthetic_motion(3);
        bad[2][4][1] = f64::NAN;
        assert_eq!(
            write_glb(&bad, 20.0, JointNames::Smpl),
            Err(GltfError::NonFinite(2))
        );
        assert_eq!(
            write_glb(&poses, 0.0, JointNames::Smpl),
            Err(GltfError::FrameRate(0.0))
        );
    }
}
