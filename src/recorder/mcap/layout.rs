//! A Foxglove Studio layout for a run of a given model (Layouts → Import): the arm in 3D with the
//! tool's path, a plot of every joint's angle against its target and one plot per joint of its
//! torque (scaled to the motion's own torque, the limit beside it where near: `TorqueAxis`),
//! labelled with the model's own joint names. Written beside each `.mcap`.

use crate::dynamics::{body_poses, frame_pose_in};
use crate::model::Model;
use crate::spatial::Pose;
use crate::recorder::shared::plot_colours::{FRICTION_RGB, LIMIT_RGB, MEASURED_RGB, TARGET_RGB, hex, joint_rgb, observed_rgb};
use crate::recorder::shared::torque_axis::TorqueAxis;
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

/// A series drawn in `colour` (the `.rrd`'s colours: a joint's own, the target grey, the limit red).
fn coloured(path: String, label: String, colour: (u8, u8, u8)) -> Value {
    let mut s = series(path, label);
    s["color"] = json!(hex(colour));
    s
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

/// What a run's plots show beyond angles and torques.
#[derive(Default)]
pub struct RunPlots<'a> {
    /// `--motors`: each joint's speed-dependent torque limit beside its torque.
    pub motors: bool,
    /// Some joint has friction (its URDF's or its gearbox's): each joint's friction torque too.
    pub friction: bool,
    /// Per joint, driven open loop (stepper mode): a plot of load angles and lost steps.
    pub stepped: &'a [bool],
    /// Per joint, a replayed recording's measured effort beside the model's torque (empty: none).
    pub measured: &'a [bool],
    /// Per joint, a forward replay's real follower beside the simulated position (empty: none).
    pub observed: &'a [bool],
    /// Per joint, its torque plot's range.
    pub torque_axes: &'a [TorqueAxis],
    /// Per joint, its motor has thermal data: a plot of the winding temperatures.
    pub heated: &'a [bool],
    /// The run checks collisions: the links in contact shown red in 3D, a plot of the pairs in
    /// contact and the closest distance.
    pub collisions: bool,
}

/// `panels` side by side (`direction` "row") or stacked ("column"), each given an equal share.
fn split_evenly(mut panels: Vec<Value>, direction: &str) -> Value {
    if panels.len() <= 1 {
        return panels.pop().unwrap_or(Value::Null);
    }
    let second = panels.split_off(panels.len() / 2);
    let share = 100.0 * panels.len() as f64 / (panels.len() + second.len()) as f64;
    json!({ "first": split_evenly(panels, direction), "second": split_evenly(second, direction), "direction": direction, "splitPercentage": share })
}

/// The layout of a run of `model` from `q0` showing `plots`. Each joint's torque plot spans
/// ±`plots.torque_axes[i].half_range` when given.
pub fn layout_for_run(model: &Model, q0: &[f64], plots: &RunPlots) -> Value {
    let RunPlots { motors, friction, stepped, measured, observed, torque_axes, heated, collisions } = *plots;
    let (target, distance) = camera(model, q0);
    let names: Vec<&str> = model.joints.iter().map(|j| j.name.as_str()).collect();
    let angles = names
        .iter()
        .enumerate()
        .flat_map(|(i, n)| {
            let real = observed.get(i).copied().unwrap_or(false).then(|| coloured(format!("/controller.observed_position[{i}]"), format!("{n} real follower"), observed_rgb(i)));
            [coloured(format!("/joint_states.joints[{i}].position"), format!("{n} angle"), joint_rgb(i)), coloured(format!("/controller.target[{i}]"), format!("{n} target"), TARGET_RGB)].into_iter().chain(real)
        })
        .collect();
    // one plot per joint: joints' torques differ by orders of magnitude, and each is read against
    // its own limit
    let torque_plots: Vec<(String, Value)> = names
        .iter()
        .enumerate()
        .map(|(i, n)| {
            let limit = motors.then(|| coloured(format!("/controller.torque_limit[{i}]"), format!("{n} limit"), LIMIT_RGB));
            let friction = friction.then(|| coloured(format!("/controller.friction[{i}]"), format!("{n} friction"), FRICTION_RGB));
            let measured = measured.get(i).copied().unwrap_or(false).then(|| coloured(format!("/controller.measured_effort[{i}]"), format!("{n} measured effort"), MEASURED_RGB));
            let paths = std::iter::once(coloured(format!("/controller.torque[{i}]"), format!("{n} torque"), joint_rgb(i))).chain(limit).chain(friction).chain(measured).collect();
            let mut panel = plot(paths);
            if let Some(axis) = torque_axes.get(i) {
                panel["minYValue"] = json!(-axis.half_range);
                panel["maxYValue"] = json!(axis.half_range);
                panel["foxglovePanelTitle"] = json!(axis.title(n));
            }
            (format!("Plot!torque{i}"), panel)
        })
        .collect();
    let columns = names.len().div_ceil(2).clamp(1, 4);
    let torque_rows = torque_plots.chunks(columns).map(|row| split_evenly(row.iter().map(|(id, _)| json!(id)).collect(), "row")).collect();
    let torques = split_evenly(torque_rows, "column");
    let steppers: Vec<Value> = names
        .iter()
        .enumerate()
        .filter(|(i, _)| stepped.get(*i).copied().unwrap_or(false))
        .flat_map(|(i, n)| [series(format!("/controller.load_angle[{i}]"), format!("{n} load angle (el. °)")), series(format!("/controller.lost_steps[{i}]"), format!("{n} lost steps"))])
        .collect();
    let right = if steppers.is_empty() {
        json!({ "first": "Plot!angles", "second": torques, "direction": "column", "splitPercentage": 34 })
    } else {
        json!({ "first": "Plot!angles", "second": { "first": torques, "second": "Plot!steppers", "direction": "column", "splitPercentage": 67 }, "direction": "column", "splitPercentage": 25 })
    };
    let visible = |topics: &[&str]| topics.iter().map(|t| (t.to_string(), json!({ "visible": true }))).collect::<serde_json::Map<_, _>>();
    let has_steppers = !steppers.is_empty();
    let temperatures: Vec<Value> = names
        .iter()
        .enumerate()
        .filter(|(i, _)| heated.get(*i).copied().unwrap_or(false))
        .map(|(i, n)| coloured(format!("/controller.winding_temperature[{i}]"), format!("{n} winding (°C)"), joint_rgb(i)))
        .collect();
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
                "topics": Value::Object(visible(&["/tf", "/robot/geometry", "/tool/path", "/tool/commanded_path", "/tool/pose", "/collisions/contacts"])),
                "layers": {
                    "grid": {
                        "visible": true, "frameLocked": true, "label": "Grid", "instanceId": "grid", "layerId": "foxglove.Grid",
                        "size": 2, "divisions": 20, "lineWidth": 1, "color": "#248eff", "position": [0, 0, 0], "rotation": [0, 0, 0], "order": 1
                    }
                }
            },
            "Plot!angles": plot(angles)
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
    for (id, panel) in torque_plots {
        doc["configById"][id] = panel;
    }
    if !temperatures.is_empty() {
        // below the arm: the windings heat over minutes, the plot beside the 3D view reads it
        doc["configById"]["Plot!temperatures"] = plot(temperatures);
        let arm = doc["layout"]["first"].take();
        doc["layout"]["first"] = json!({ "first": arm, "second": "Plot!temperatures", "direction": "column", "splitPercentage": 70 });
    }
    if has_steppers {
        doc["configById"]["Plot!steppers"] = plot(steppers);
    }
    if collisions {
        // below the arm, as the temperatures: when and how close
        doc["configById"]["Plot!collisions"] = plot(vec![series("/collisions.in_contact".into(), "pairs in contact".into()), series("/collisions.min_distance".into(), "closest pair (m; < 0: overlap)".into())]);
        let arm = doc["layout"]["first"].take();
        doc["layout"]["first"] = json!({ "first": arm, "second": "Plot!collisions", "direction": "column", "splitPercentage": 75 });
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
        let path = root.join("assets/foxglove/armscope_layout.json");
        let expected = layout_for_run(&model, &vec![0.0; model.dof()], &RunPlots::default());
        if std::env::var_os("ARMSCOPE_REGENERATE").is_some() {
            std::fs::write(&path, serde_json::to_string_pretty(&expected).unwrap() + "\n").unwrap();
        }
        let committed: Value = serde_json::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap();
        assert_eq!(committed, expected, "regenerate assets/foxglove/armscope_layout.json (ARMSCOPE_REGENERATE=1 cargo test the_committed_layout)");
    }

    /// The panel ids the layout tree places, in order.
    fn placed(tree: &Value, out: &mut Vec<String>) {
        match tree {
            Value::String(id) => out.push(id.clone()),
            Value::Object(split) => {
                placed(&split["first"], out);
                placed(&split["second"], out);
            }
            _ => panic!("not a layout tree: {tree}"),
        }
    }

    #[test]
    fn every_joint_has_its_own_torque_plot_with_its_axis() {
        let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
        let model = crate::model::load_urdf(&root.join(crate::builtin::DEFAULT_URDF)).unwrap();
        let n = model.dof();
        let axes: Vec<TorqueAxis> = (0..n).map(|i| TorqueAxis::new(0.1 * (i + 1) as f64, 35.0)).collect();
        let stepped = [false, true, false, false, false, false];
        let heated = [false, true, false, false, false, false];
        let l = layout_for_run(&model, &vec![0.0; n], &RunPlots { motors: true, friction: true, stepped: &stepped, measured: &[], observed: &[], torque_axes: &axes, heated: &heated, collisions: false });
        // the tree places every configured panel exactly once, and only those
        let mut ids = Vec::new();
        placed(&l["layout"], &mut ids);
        let mut configured: Vec<String> = l["configById"].as_object().unwrap().keys().cloned().collect();
        let mut sorted = ids.clone();
        sorted.sort();
        configured.sort();
        assert_eq!(sorted, configured);
        for (i, axis) in axes.iter().enumerate() {
            let panel = &l["configById"][format!("Plot!torque{i}")];
            assert_eq!(panel["maxYValue"], json!(axis.half_range));
            assert_eq!(panel["minYValue"], json!(-axis.half_range));
            assert_eq!(panel["paths"][1]["value"], json!(format!("/controller.torque_limit[{i}]")));
            assert_eq!(panel["paths"][2]["value"], json!(format!("/controller.friction[{i}]")));
            // drawn as the .rrd draws them: the joint's own colour, the limit red, friction magenta
            let colours: Vec<&str> = panel["paths"].as_array().unwrap().iter().map(|p| p["color"].as_str().unwrap()).collect();
            assert_eq!(colours, [hex(joint_rgb(i)), hex(LIMIT_RGB), hex(FRICTION_RGB)]);
            let angles = &l["configById"]["Plot!angles"]["paths"];
            assert_eq!((angles[2 * i]["color"].as_str().unwrap(), angles[2 * i + 1]["color"].as_str().unwrap()), (hex(joint_rgb(i)).as_str(), hex(TARGET_RGB).as_str()));
        }
        // the one motor with thermal data: its winding temperature
        assert_eq!(l["configById"]["Plot!temperatures"]["paths"].as_array().unwrap().len(), 1);
        assert_eq!(l["configById"]["Plot!temperatures"]["paths"][0]["value"], "/controller.winding_temperature[1]");
        // the torque plots are placed in joint order
        let torque_ids: Vec<&String> = ids.iter().filter(|id| id.starts_with("Plot!torque")).collect();
        assert_eq!(torque_ids, (0..n).map(|i| format!("Plot!torque{i}")).collect::<Vec<_>>().iter().collect::<Vec<_>>());
    }

    #[test]
    fn plots_are_labelled_with_the_models_joint_names() {
        let urdf = r#"<robot name="two"><link name="base"/><link name="a"><inertial><mass value="1"/><inertia ixx="1" iyy="1" izz="1" ixy="0" ixz="0" iyz="0"/></inertial></link>
            <joint name="shoulder_pan" type="continuous"><parent link="base"/><child link="a"/><axis xyz="0 0 1"/></joint></robot>"#;
        let model = crate::model::load_urdf_str(urdf, std::path::Path::new("two.urdf")).unwrap();
        let l = layout_for_run(&model, &[0.0], &RunPlots::default());
        let labels: Vec<&str> = l["configById"]["Plot!angles"]["paths"].as_array().unwrap().iter().map(|p| p["label"].as_str().unwrap()).collect();
        assert_eq!(labels, ["shoulder_pan angle", "shoulder_pan target"]);
        assert_eq!(l["configById"]["Plot!torque0"]["paths"][0]["label"], "shoulder_pan torque");
    }
}
