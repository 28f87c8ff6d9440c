//! A Foxglove Studio layout for a run of a given model (Layouts → Import): the arm in 3D with the
//! tool's path, and plots of every joint's angle against its target and of every joint's torque,
//! labelled with the model's own joint names. Written beside each `.mcap`.

use crate::dynamics::{body_poses, frame_pose_in};
use crate::model::Model;
use crate::spatial::Pose;
use serde_json::{Value, json};

/// The plot settings every plot panel shares.
fn plot(paths: Vec<Value>) -> Value {
    json!({
        "paths": paths,
        "showLegend": true,
        "legendDisplay": "floating",
        "showPlotValuesInLegend": false,
        "showXAxisLabels": true,
        "showYAxisLabels": true,
        "isSynced": true,
        "xAxisVal": "timestamp",
        "sidebarDimension": 240
    })
}

fn series(path: String, label: String) -> Value {
    json!({ "value": path, "enabled": true, "timestampMethod": "receiveTime", "label": label })
}

/// Where the camera looks and from how far: the middle of the links at `q`, from 4× their spread
/// (at least 0.6 m).
fn camera(model: &Model, q: &[f64]) -> ([f64; 3], f64) {
    let mut poses = vec![Pose::identity(); model.bodies.len()];
    body_poses(model, q, &mut poses);
    let points: Vec<_> = (0..model.frames.len()).map(|f| frame_pose_in(model, &poses, f).translation).collect();
    let (mut lo, mut hi) = (points[0], points[0]);
    for p in &points {
        lo = lo.inf(p);
        hi = hi.sup(p);
    }
    let centre = (lo + hi) / 2.0;
    let spread = (hi - lo).norm();
    ([centre.x, centre.y, centre.z], (4.0 * spread).max(0.6))
}

/// The layout for `model`, whose run starts at joint positions `q0`.
pub fn layout(model: &Model, q0: &[f64]) -> Value {
    layout_with_motors(model, q0, false, &[])
}

/// With `--motors` (`motors`): each joint's speed-dependent torque limit beside its torque; with
/// steppers driven open loop (`stepped`): a third plot of their load angles and lost steps.
pub fn layout_with_motors(model: &Model, q0: &[f64], motors: bool, stepped: &[bool]) -> Value {
    let (target, distance) = camera(model, q0);
    let names: Vec<&str> = model.joints.iter().map(|j| j.name.as_str()).collect();
    let angles = names
        .iter()
        .enumerate()
        .flat_map(|(i, n)| [series(format!("/joint_states.joints[{i}].position"), format!("{n} angle")), series(format!("/controller.target[{i}]"), format!("{n} target"))])
        .collect();
    let torques = names
        .iter()
        .enumerate()
        .flat_map(|(i, n)| {
            let limit = motors.then(|| series(format!("/controller.torque_limit[{i}]"), format!("{n} limit")));
            std::iter::once(series(format!("/controller.torque[{i}]"), format!("{n} torque"))).chain(limit)
        })
        .collect();
    let steppers: Vec<Value> = names
        .iter()
        .enumerate()
        .filter(|(i, _)| stepped.get(*i).copied().unwrap_or(false))
        .flat_map(|(i, n)| [series(format!("/controller.load_angle[{i}]"), format!("{n} load angle (el. °)")), series(format!("/controller.lost_steps[{i}]"), format!("{n} lost steps"))])
        .collect();
    let right = if steppers.is_empty() {
        json!({ "first": "Plot!angles", "second": "Plot!torques", "direction": "column", "splitPercentage": 50 })
    } else {
        json!({ "first": "Plot!angles", "second": { "first": "Plot!torques", "second": "Plot!steppers", "direction": "column", "splitPercentage": 50 }, "direction": "column", "splitPercentage": 34 })
    };
    let visible = |topics: &[&str]| topics.iter().map(|t| (t.to_string(), json!({ "visible": true }))).collect::<serde_json::Map<_, _>>();
    let has_steppers = !steppers.is_empty();
    let mut doc = json!({
        "configById": {
            "3D!arm": {
                "followTf": "world",
                "followMode": "follow-none",
                "cameraState": {
                    "distance": distance, "phi": 60, "thetaOffset": 35, "target": target, "perspective": true,
                    "fovy": 45, "near": 0.01, "far": 5000, "targetOffset": [0, 0, 0], "targetOrientation": [0, 0, 0, 1]
                },
                "scene": { "transforms": { "showLabel": false, "axisScale": 0.4 } },
                "transforms": {},
                "topics": Value::Object(visible(&["/tf", "/robot/geometry", "/tool/path", "/tool/commanded_path", "/tool/pose"])),
                "layers": {
                    "grid": {
                        "visible": true, "frameLocked": true, "label": "Grid", "instanceId": "grid", "layerId": "foxglove.Grid",
                        "size": 2, "divisions": 20, "lineWidth": 1, "color": "#248eff", "position": [0, 0, 0], "rotation": [0, 0, 0], "order": 1
                    }
                }
            },
            "Plot!angles": plot(angles),
            "Plot!torques": plot(torques)
        },
        "globalVariables": {},
        "userNodes": {},
        "playbackConfig": { "speed": 1 },
        "layout": {
            "first": "3D!arm",
            "second": right,
            "direction": "row",
            "splitPercentage": 50
        }
    });
    if has_steppers {
        doc["configById"]["Plot!steppers"] = plot(steppers);
    }
    doc
}

/// Where the layout of the recording `mcap` goes: `NAME.layout.json` beside it.
pub fn layout_path(mcap: &std::path::Path) -> std::path::PathBuf {
    mcap.with_extension("layout.json")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_committed_layout_is_the_box_models() {
        let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
        let model = crate::model::load_urdf(&root.join(crate::builtin::DEFAULT_URDF)).unwrap();
        let committed: Value = serde_json::from_str(&std::fs::read_to_string(root.join("assets/foxglove/armscope_layout.json")).unwrap()).unwrap();
        assert_eq!(committed, layout(&model, &vec![0.0; model.dof()]), "regenerate assets/foxglove/armscope_layout.json");
    }

    #[test]
    fn plots_are_labelled_with_the_models_joint_names() {
        let urdf = r#"<robot name="two"><link name="base"/><link name="a"><inertial><mass value="1"/><inertia ixx="1" iyy="1" izz="1" ixy="0" ixz="0" iyz="0"/></inertial></link>
            <joint name="shoulder_pan" type="continuous"><parent link="base"/><child link="a"/><axis xyz="0 0 1"/></joint></robot>"#;
        let model = crate::model::load_urdf_str(urdf, std::path::Path::new("two.urdf")).unwrap();
        let l = layout(&model, &[0.0]);
        let labels: Vec<&str> = l["configById"]["Plot!angles"]["paths"].as_array().unwrap().iter().map(|p| p["label"].as_str().unwrap()).collect();
        assert_eq!(labels, ["shoulder_pan angle", "shoulder_pan target"]);
        assert_eq!(l["configById"]["Plot!torques"]["paths"][0]["label"], "shoulder_pan torque");
    }
}
