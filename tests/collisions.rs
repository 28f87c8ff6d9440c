//! Collision checks (issue 23, the geometry and the distances): each link's `<collision>` shapes,
//! the active pairs, and per state the distance of every pair closer than 5 cm (negative inside),
//! against Pinocchio 4.1 + coal on the same shapes and pairs (tests/fixtures/collisions, made by its
//! make_fixture.py; `.ci/collisions-vs-coal.py` does the same live on example-robot-data's robots).

mod common;

use armscope::collision::Collisions;
use armscope::model::load_urdf;
use serde_json::Value;

/// At 40 random states of the box model (boxes) and of the SmallRobotArm mesh model (STL meshes):
/// the same active pairs as the fixture's, and per pair the same answer as coal — the distance within
/// 1e-6 m for boxes and 1e-5 m for meshes where both are apart and closer than 5 cm, in contact on
/// both sides where coal finds contact, absent where coal measures more than 5 cm; pairs within 1 mm
/// of touching may go either way.
#[test]
fn distances_are_coals_on_the_same_shapes_and_pairs() {
    // (the mesh model's links never touch at these states: its contact cases are left to the CI check)
    for (file, tolerance, min_contacts) in [("box_model.json", 1e-6, 1), ("smallrobotarm_meshes.json", 1e-5, 0)] {
        let fixture = collision_fixture(file);
        let model = load_urdf(&common::repo().join(fixture["urdf"].as_str().unwrap())).unwrap();
        assert_matches_coal(&model, &fixture, file, tolerance, min_contacts);
    }
}

/// The SmallRobotArm's meshes written as COLLADA — in millimetres (`<unit meter="0.001">`), Y up,
/// each placed by a node transform nested under a turned parent node — are the same surfaces as the
/// STL files: the same distances as coal's on the STL model, within the same 1e-5 m (the file's
/// single-precision millimetres are 3e-8 m apart at the arm's reach).
#[test]
fn collada_meshes_with_units_up_axis_and_nodes_give_coals_distances() {
    let dir = tempfile::tempdir().unwrap();
    let urdf_path = collada_smallrobotarm(dir.path());
    let package = urdf_path.parent().unwrap();
    let model = load_urdf(&urdf_path).unwrap();
    // every link's shapes were read: none left out
    let collisions = armscope::collision::geometry::CollisionModel::new(&model);
    assert!(collisions.left_out.is_empty(), "{:?}", collisions.left_out);
    // and the turn is said, once per file
    let turned: Vec<_> = model.notices.iter().filter(|n| n.contains("Y_UP")).collect();
    assert_eq!(turned.len(), std::fs::read_dir(package.join("meshes")).unwrap().count(), "{:?}", model.notices);
    assert!(turned[0].starts_with("link '") && turned[0].contains(".dae"), "{}", turned[0]);
    assert_matches_coal(&model, &collision_fixture("smallrobotarm_meshes.json"), "COLLADA SmallRobotArm", 1e-5, 0);
}

/// The SmallRobotArm mesh model with each STL mesh written as COLLADA ([`collada_mm_y_up`]) in
/// `dir/smallrobotarm`, with its SRDF; returns the URDF's path.
fn collada_smallrobotarm(dir: &std::path::Path) -> std::path::PathBuf {
    let package = dir.join("smallrobotarm");
    std::fs::create_dir_all(package.join("meshes")).unwrap();
    let assets = common::repo().join("assets/smallrobotarm");
    for entry in std::fs::read_dir(assets.join("meshes")).unwrap() {
        let path = entry.unwrap().path();
        let mesh = armscope::model::mesh_file::read_mesh(&path).unwrap();
        let (vertices, triangles) = mesh.welded([1.0; 3]);
        let name = path.file_stem().unwrap().to_str().unwrap();
        std::fs::write(package.join("meshes").join(format!("{name}.dae")), collada_mm_y_up(&vertices, &triangles)).unwrap();
    }
    let urdf = std::fs::read_to_string(assets.join("smallrobotarm.urdf")).unwrap().replace(".stl\"", ".dae\"");
    let urdf_path = package.join("smallrobotarm.urdf");
    std::fs::write(&urdf_path, urdf).unwrap();
    std::fs::copy(assets.join("smallrobotarm.srdf"), package.join("smallrobotarm.srdf")).unwrap();
    urdf_path
}

/// A run of the COLLADA model draws each link's mesh in the `.rrd` as a Rerun mesh (Rerun reads no
/// COLLADA itself) with every triangle of the file, and the MCAP carries the file as a COLLADA model
/// for Foxglove.
#[test]
fn collada_visuals_are_drawn_in_both_recordings() {
    let dir = tempfile::tempdir().unwrap();
    let urdf = collada_smallrobotarm(dir.path());
    let (rrd, mcap) = (dir.path().join("dae.rrd"), dir.path().join("dae.mcap"));
    assert_eq!(common::armscope(&["run", "--urdf", urdf.to_str().unwrap(), "--duration", "0.1", "--rrd", rrd.to_str().unwrap(), "--mcap", mcap.to_str().unwrap()]), 0);
    let model = load_urdf(&urdf).unwrap();
    let rrd = common::rrd::Rrd::open(&rrd);
    let entities = rrd.entities();
    for frame in model.frames.iter().filter(|f| !f.visuals.is_empty()) {
        let armscope::model::Geometry::Mesh { path, .. } = &frame.visuals[0].geometry else { panic!("{}: a mesh", frame.name) };
        let triangles = armscope::model::mesh_file::read_mesh(path).unwrap().triangle_count();
        let entity = entities.keys().find(|e| e.ends_with(&format!("/{}/visual_0", frame.name))).unwrap_or_else(|| panic!("{}'s visual in {:?}", frame.name, entities.keys()));
        assert_eq!(rrd.static_instances(entity, "Mesh3D:triangle_indices"), triangles, "{entity}");
    }
    let bytes = std::fs::read(&mcap).unwrap();
    let geometry = mcap::MessageStream::new(&bytes).unwrap().map(|m| m.unwrap()).find(|m| m.channel.topic == "/robot/geometry").expect("the geometry");
    let text = String::from_utf8_lossy(&geometry.data);
    assert_eq!(text.matches("model/vnd.collada+xml").count(), model.frames.iter().filter(|f| !f.visuals.is_empty()).count());
}

/// A COLLADA file that is not one (here cut short) leaves the run whole: the link is left out of the
/// collision checks and undrawn in the `.rrd`, each said in a notice naming the link and the file.
#[test]
fn an_unreadable_collada_mesh_is_a_notice_naming_the_link_and_the_file() {
    let dir = tempfile::tempdir().unwrap();
    let urdf = collada_smallrobotarm(dir.path());
    let broken = urdf.parent().unwrap().join("meshes/link2.dae");
    let text = std::fs::read_to_string(&broken).unwrap();
    std::fs::write(&broken, &text[..text.len() / 2]).unwrap();
    let rrd = dir.path().join("broken.rrd");
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_armscope"))
        .args(["run", "--urdf", urdf.to_str().unwrap(), "--duration", "0.1", "--collisions", "--rrd", rrd.to_str().unwrap(), "--no-mcap"])
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    for what in ["left out of the collision checks", "not drawn"] {
        let notice = stderr.lines().find(|l| l.contains(what)).unwrap_or_else(|| panic!("a notice '{what}' in {stderr}"));
        assert!(notice.contains("link 'link2'") && notice.contains("link2.dae"), "{notice}");
    }
    assert!(rrd.exists());
}

/// A COLLADA document of `vertices` (m, Z up): written in millimetres with Y up, under a parent
/// node turned a quarter about the file's y and a child node shifted 10 mm, the file's numbers
/// undoing both.
fn collada_mm_y_up(vertices: &[[f64; 3]], triangles: &[[u32; 3]]) -> String {
    // a point p (Z up) is the file's (p.x, p.z, −p.y) under Y up; the parent's turn about the
    // file's y, (x, y, z) ↦ (z, y, −x), is undone by (x, y, z) ↦ (−z, y, x); the child's shift by −10
    let file: Vec<String> = vertices
        .iter()
        .map(|p| {
            let (x, y, z) = (p[0] * 1000.0, p[2] * 1000.0, -p[1] * 1000.0);
            let (x, y, z) = (-z, y, x);
            format!("{} {} {}", x - 10.0, y, z)
        })
        .collect();
    let indices: Vec<String> = triangles.iter().map(|t| format!("{} {} {}", t[0], t[1], t[2])).collect();
    format!(
        r##"<?xml version="1.0" encoding="utf-8"?>
<COLLADA xmlns="http://www.collada.org/2005/11/COLLADASchema" version="1.4.1">
  <asset><unit name="millimeter" meter="0.001"/><up_axis>Y_UP</up_axis></asset>
  <library_geometries><geometry id="part" name="part"><mesh>
    <source id="part-positions"><float_array id="part-positions-array" count="{n3}">{positions}</float_array>
      <technique_common><accessor source="#part-positions-array" count="{n}" stride="3"><param name="X" type="float"/><param name="Y" type="float"/><param name="Z" type="float"/></accessor></technique_common></source>
    <vertices id="part-vertices"><input semantic="POSITION" source="#part-positions"/></vertices>
    <triangles count="{t}"><input semantic="VERTEX" source="#part-vertices" offset="0"/><p>{indices}</p></triangles>
  </mesh></geometry></library_geometries>
  <library_visual_scenes><visual_scene id="scene">
    <node id="turned"><rotate>0 1 0 90</rotate><node id="shifted"><translate>10 0 0</translate><instance_geometry url="#part"/></node></node>
  </visual_scene></library_visual_scenes>
  <scene><instance_visual_scene url="#scene"/></scene>
</COLLADA>
"##,
        n3 = 3 * vertices.len(),
        n = vertices.len(),
        t = triangles.len(),
        positions = file.join(" "),
        indices = indices.join(" "),
    )
}

fn collision_fixture(file: &str) -> Value {
    serde_json::from_str(&std::fs::read_to_string(common::repo().join("tests/fixtures/collisions").join(file)).unwrap()).unwrap()
}

fn assert_matches_coal(model: &armscope::model::Model, fixture: &Value, file: &str, tolerance: f64, min_contacts: usize) {
    let c = Collisions::new(model, None, &Default::default()).unwrap();
    let pairs: Vec<(String, String)> = c.pairs.iter().map(|&(a, b)| (model.frames[a].name.clone(), model.frames[b].name.clone())).collect();
    let expected: Vec<(String, String)> = fixture["pairs"].as_array().unwrap().iter().map(|p| (p[0].as_str().unwrap().to_string(), p[1].as_str().unwrap().to_string())).collect();
    assert_eq!(pairs, expected, "{file}: the active pairs");
    let (mut compared, mut contacts) = (0, 0);
    for state in fixture["states"].as_array().unwrap() {
        let q: Vec<f64> = model.joints.iter().map(|j| state["q"][&j.name].as_f64().unwrap()).collect();
        let ours = c.at(model, &q, 0.05);
        for ((a, b), coal) in expected.iter().zip(state["distances"].as_array().unwrap()) {
            let coal = coal.as_f64().unwrap();
            let mine = ours.iter().find(|(x, y, _)| x == a && y == b).map(|p| p.2);
            if coal.abs() < 1e-3 || mine.is_some_and(|m| m.abs() < 1e-3) {
                continue;
            }
            match mine {
                None => assert!(coal > 0.05 - tolerance, "{file}: {a}–{b} at {q:?}: coal {coal}, armscope beyond 5 cm"),
                Some(m) if coal <= 0.0 => {
                    assert!(m <= 0.0, "{file}: {a}–{b}: coal in contact ({coal}), armscope {m}");
                    contacts += 1;
                }
                Some(m) => {
                    assert!((m - coal).abs() <= tolerance, "{file}: {a}–{b}: coal {coal}, armscope {m}");
                    compared += 1;
                }
            }
        }
    }
    assert!(compared >= 20 && contacts >= min_contacts, "{file}: {compared} distances and {contacts} contacts compared");
}

/// At the box model's zero pose (the arm level at 0.26 m, the carrier's box from 0.1 to 0.26 m), a
/// floor at 0.2 m: the upper arm's box (0.23–0.29 m) is 0.03 m above it, the carrier's 0.1 m into it;
/// the base, welded to the world, is not checked against it.
#[test]
fn a_floor_is_a_half_space_at_its_height() {
    let model = load_urdf(&common::box_urdf()).unwrap();
    let scene = armscope::collision::Scene { floor: Some(0.2), ..Default::default() };
    let c = Collisions::new(&model, None, &scene).unwrap();
    let close = c.at(&model, &[0.0; 6], 0.05);
    let floor = |link: &str| close.iter().find(|(a, b, _)| a == link && b == "floor").map(|p| p.2);
    assert!((floor("upper_arm_link").unwrap() - 0.03).abs() < 1e-9, "{close:?}");
    assert!((floor("carrier_link").unwrap() + 0.1).abs() < 1e-6, "{close:?}");
    assert_eq!(floor("base_link"), None);
}

/// An SRDF's <disable_collisions> pairs are not checked, in either order; a malformed one gets one
/// line naming the file and the line.
#[test]
fn an_srdf_disables_pairs_and_a_bad_one_is_named() {
    let dir = tempfile::tempdir().unwrap();
    let model = load_urdf(&common::box_urdf()).unwrap();
    let all = Collisions::new(&model, None, &Default::default()).unwrap().pairs.len();
    let srdf = dir.path().join("arm.srdf");
    std::fs::write(&srdf, r#"<robot name="a"><disable_collisions link1="tool_link" link2="base_link" reason="Never"/><disable_collisions link1="nowhere" link2="base_link"/></robot>"#).unwrap();
    let c = Collisions::new(&model, Some(&srdf), &Default::default()).unwrap();
    assert_eq!(c.pairs.len(), all - 1);
    assert!(!c.pairs.iter().any(|&(a, b)| [&model.frames[a].name, &model.frames[b].name] == ["base_link", "tool_link"]));
    assert!(c.notices.iter().any(|n| n.contains("nowhere")), "an unknown link is said");
    std::fs::write(&srdf, "<robot>\n<disable_collisions link1=\"tool_link\"/>\n</robot>").unwrap();
    let e = Collisions::new(&model, Some(&srdf), &Default::default()).err().unwrap().to_string();
    assert!(!e.contains('\n') && e.contains("arm.srdf") && e.contains("line 2") && e.contains("link2"), "{e}");
}

/// `run --floor Z`: the box model's default wave takes its tool below the base. With a floor at
/// −0.2 m the run's first contact is the tool with the floor, at the first control step where the
/// lowest corner of the tool's box (0.04 × 0.18 × 0.03 m about (0.02, 0, 0) in its link frame), put
/// where the trace's joint angles place it, is at or below the floor — an independent reading of the
/// same state — and the summary's deepest overlap is that corner's deepest.
#[test]
fn a_run_flags_the_floor_when_the_tool_reaches_it() {
    let dir = tempfile::tempdir().unwrap();
    let (trace, summary) = (dir.path().join("trace.csv"), dir.path().join("summary.json"));
    let code = common::armscope(&["run", "--quiet", "--floor", "-0.2", "--duration", "3", "--trace", trace.to_str().unwrap(), "--summary-json", summary.to_str().unwrap()]);
    assert_eq!(code, 0);
    let s: Value = serde_json::from_str(&std::fs::read_to_string(&summary).unwrap()).unwrap();
    let c = &s["summary"]["collisions"];
    let first = &c["first_contact"];
    assert_eq!((first[1].as_str(), first[2].as_str()), (Some("tool_link"), Some("floor")), "{c}");
    let model = load_urdf(&common::box_urdf()).unwrap();
    let tool = model.frame_index("tool_link").unwrap();
    let table = common::read_csv(&trace);
    let mut data = armscope::dynamics::Data::new(&model);
    let (mut first_below, mut deepest) = (None, 0.0f64);
    for row in &table.rows {
        let q: Vec<f64> = (1..=6).map(|i| row[table.col(&format!("q{i}"))]).collect();
        armscope::dynamics::forward_kinematics(&model, &mut data, &q);
        let pose = armscope::dynamics::frame_pose(&model, &data, tool);
        let lowest = [-1.0, 1.0].iter().flat_map(|&x| [-1.0, 1.0].iter().flat_map(move |&y| [-1.0, 1.0].map(move |z| nalgebra::Vector3::new(0.02 + 0.02 * x, 0.09 * y, 0.015 * z)))).map(|p| pose.transform_point(&p).z).fold(f64::INFINITY, f64::min);
        if lowest <= -0.2 && first_below.is_none() {
            first_below = Some(row[table.col("t")]);
        }
        deepest = deepest.max(-0.2 - lowest);
    }
    assert_eq!(first[0].as_f64(), first_below, "the first contact is the first step the tool's lowest corner reaches the floor");
    let tool_floor = c["pairs"].as_array().unwrap().iter().find(|p| p["link1"] == "tool_link" && p["link2"] == "floor").unwrap();
    assert!((-tool_floor["closest"].as_f64().unwrap() - deepest).abs() < 1e-9, "deepest {deepest} vs {tool_floor}");
}

/// A scene file's table and payload: the box model's default wave dips its tool through a table top
/// at z = −0.15 m (a slab 2 × 2 × 0.3 m, wider than the arm's reach) while it carries a ball of 4 cm
/// radius 0.1 m out along the tool's x axis. The run's first contact is the tool (ball included) with
/// the table, at the first control step where the lowest point of the tool's box or of the ball, put
/// where the trace's joint angles place them, reaches the table top — an independent reading of the
/// same states; without the ball the contact comes later.
#[test]
fn a_scene_table_is_flagged_when_the_payload_dips_into_it() {
    let dir = tempfile::tempdir().unwrap();
    let scene = dir.path().join("scene.toml");
    std::fs::write(&scene, "[[object]]\nname = \"table\"\nshape = \"box\"\nsize = [2.0, 2.0, 0.3]\nxyz = [0.0, 0.0, -0.3]\n\n[payload]\nshape = \"sphere\"\nradius = 0.04\nxyz = [0.1, 0.0, 0.0]\n").unwrap();
    let bare = dir.path().join("bare.toml");
    std::fs::write(&bare, "[[object]]\nname = \"table\"\nshape = \"box\"\nsize = [2.0, 2.0, 0.3]\nxyz = [0.0, 0.0, -0.3]\n").unwrap();
    let run = |scene: &std::path::Path, name: &str| {
        let (trace, summary) = (dir.path().join(format!("{name}.csv")), dir.path().join(format!("{name}.json")));
        assert_eq!(common::armscope(&["run", "--quiet", "--scene", scene.to_str().unwrap(), "--duration", "3", "--trace", trace.to_str().unwrap(), "--summary-json", summary.to_str().unwrap()]), 0);
        let s: Value = serde_json::from_str(&std::fs::read_to_string(&summary).unwrap()).unwrap();
        (common::read_csv(&trace), s["summary"]["collisions"].clone())
    };
    let (table, c) = run(&scene, "ball");
    let first = &c["first_contact"];
    assert_eq!((first[1].as_str(), first[2].as_str()), (Some("tool_link"), Some("table")), "{c}");
    assert_eq!(c["scene_objects"][0], "table");
    let model = load_urdf(&common::box_urdf()).unwrap();
    let tool = model.frame_index("tool_link").unwrap();
    let mut data = armscope::dynamics::Data::new(&model);
    let (mut first_box, mut first_any) = (None, None);
    for row in &table.rows {
        let q: Vec<f64> = (1..=6).map(|i| row[table.col(&format!("q{i}"))]).collect();
        armscope::dynamics::forward_kinematics(&model, &mut data, &q);
        let pose = armscope::dynamics::frame_pose(&model, &data, tool);
        let box_lowest = [-1.0, 1.0].iter().flat_map(|&x| [-1.0, 1.0].iter().flat_map(move |&y| [-1.0, 1.0].map(move |z| nalgebra::Vector3::new(0.02 + 0.02 * x, 0.09 * y, 0.015 * z)))).map(|p| pose.transform_point(&p).z).fold(f64::INFINITY, f64::min);
        let ball_lowest = pose.transform_point(&nalgebra::Vector3::new(0.1, 0.0, 0.0)).z - 0.04;
        let t = row[table.col("t")];
        if box_lowest <= -0.15 && first_box.is_none() {
            first_box = Some(t);
        }
        if box_lowest.min(ball_lowest) <= -0.15 && first_any.is_none() {
            first_any = Some(t);
        }
    }
    assert_eq!(first[0].as_f64(), first_any, "the first contact is the first step the tool or its ball reaches the table top");
    let (_, without) = run(&bare, "bare");
    assert_eq!(without["first_contact"][0].as_f64(), first_box, "without the ball: the tool's box");
    assert!(first_any < first_box, "the ball reaches the table first: {first_any:?} vs {first_box:?}");
}

/// `--stop-on-collision` ends the run at the first contact, exit code 4: the trace's last step is the
/// first contact's time, which a run without the flag reports too; the summary says why it stopped.
#[test]
fn stop_on_collision_ends_the_run_at_the_first_contact() {
    let dir = tempfile::tempdir().unwrap();
    let (full, stopped, trace) = (dir.path().join("full.json"), dir.path().join("stopped.json"), dir.path().join("trace.csv"));
    assert_eq!(common::armscope(&["run", "--quiet", "--floor", "-0.2", "--duration", "2", "--summary-json", full.to_str().unwrap()]), 0);
    assert_eq!(common::armscope(&["run", "--quiet", "--floor", "-0.2", "--duration", "2", "--stop-on-collision", "--trace", trace.to_str().unwrap(), "--summary-json", stopped.to_str().unwrap()]), 4);
    let read = |p: &std::path::Path| -> Value { serde_json::from_str(&std::fs::read_to_string(p).unwrap()).unwrap() };
    let first = read(&full)["summary"]["collisions"]["first_contact"][0].as_f64().unwrap();
    let status = &read(&stopped)["summary"]["status"];
    assert_eq!((status["state"].as_str(), status["time"].as_f64()), (Some("collided"), Some(first)), "{status}");
    assert_eq!((status["link1"].as_str(), status["link2"].as_str()), (Some("tool_link"), Some("floor")));
    let t = common::read_csv(&trace).column("t");
    assert_eq!(t.last().copied(), Some(first), "the trace ends at the contact");
}

/// `armscope trajectory` checks the IK path before writing it: the trajectory lab's circle on the box
/// model touches nothing; with a floor at 0.2 m (inside the carrier's box, 0.1–0.26 m) every point is
/// in contact, from t = 0, and the notice names the pair.
#[test]
fn the_trajectory_lab_checks_its_path() {
    let dir = tempfile::tempdir().unwrap();
    let run = |extra: &[&str]| {
        let out = std::process::Command::new(env!("CARGO_BIN_EXE_armscope"))
            .args(["trajectory", "circle", "--urdf", common::box_urdf().to_str().unwrap(), "--out", dir.path().join("circle").to_str().unwrap()])
            .args(extra)
            .output()
            .unwrap();
        assert!(out.status.success());
        String::from_utf8_lossy(&out.stdout).into_owned() + &String::from_utf8_lossy(&out.stderr)
    };
    let clear = run(&[]);
    assert!(clear.contains("collisions: none (15 link pairs)"), "{clear}");
    let floored = run(&["--floor", "0.2"]);
    assert!(floored.contains("the path collides: first at t = 0.000 s, carrier_link with floor; 1001 of 1001 points in contact"), "{floored}");
}

/// `model --srdf-out` writes what MoveIt's setup assistant computes: on the SmallRobotArm mesh model
/// over 2000 random states, the active pairs never (or always) in contact, and the adjacent ones. A pair
/// it calls "Never" is apart at every one of coal's fixture states too; loading the written SRDF
/// leaves exactly the other active pairs.
#[test]
fn model_writes_the_srdf_of_pairs_that_never_touch() {
    let dir = tempfile::tempdir().unwrap();
    let urdf = common::repo().join("assets/smallrobotarm/smallrobotarm.urdf");
    let srdf = dir.path().join("arm.srdf");
    // from every active pair: an empty SRDF instead of the one beside the URDF
    let empty = dir.path().join("empty.srdf");
    std::fs::write(&empty, "<robot name=\"smallrobotarm\"/>").unwrap();
    assert_eq!(common::armscope(&["model", "--urdf", urdf.to_str().unwrap(), "--srdf", empty.to_str().unwrap(), "--srdf-out", srdf.to_str().unwrap(), "--samples", "2000"]), 0);
    let text = std::fs::read_to_string(&srdf).unwrap();
    let disabled = armscope::collision::srdf::disabled_pairs(&srdf).unwrap();
    let never: Vec<&(String, String)> = disabled.iter().filter(|(a, b)| text.contains(&format!("link1=\"{a}\" link2=\"{b}\" reason=\"Never\""))).collect();
    assert!(!never.is_empty(), "{text}");
    // a "Never" pair is apart at the coal fixture's states wherever the fixture has it (the fixture's
    // pairs are those the committed SRDF leaves, which disables the same "Never" pairs from 10000 states)
    let fixture: Value = serde_json::from_str(&std::fs::read_to_string(common::repo().join("tests/fixtures/collisions/smallrobotarm_meshes.json")).unwrap()).unwrap();
    let pairs: Vec<(String, String)> = fixture["pairs"].as_array().unwrap().iter().map(|p| (p[0].as_str().unwrap().to_string(), p[1].as_str().unwrap().to_string())).collect();
    for (a, b) in &never {
        if let Some(i) = pairs.iter().position(|(x, y)| x == a && y == b) {
            assert!(fixture["states"].as_array().unwrap().iter().all(|s| s["distances"][i].as_f64().unwrap() > 0.0), "{a}–{b} touches at a fixture state");
        }
    }
    let committed = armscope::collision::srdf::disabled_pairs(&common::repo().join("assets/smallrobotarm/smallrobotarm.srdf")).unwrap();
    assert!(never.iter().all(|p| committed.contains(p)), "2000 samples find no Never pair the committed 10000-sample SRDF lacks");
    let model = load_urdf(&urdf).unwrap();
    let all = Collisions::new(&model, Some(&empty), &Default::default()).unwrap().pairs.len();
    let kept = Collisions::new(&model, Some(&srdf), &Default::default()).unwrap().pairs.len();
    let never_or_always = text.matches("reason=\"Never\"").count() + text.matches("reason=\"Always\"").count();
    assert_eq!(kept, all - never_or_always);
}

/// `size` checks the commanded motion for self-collision: a ±90° wave folds the box model's forearm
/// into its base, and the sizing says so and is no valid one (exit 1, `verified` false, the pair and
/// time in size.json); the tutorial's ±30° wave collides nowhere and sizes as before. The chosen
/// set's full simulation is checked at every control step too (with a floor: the simulated arm
/// meets it where the command does not).
#[test]
fn size_refuses_a_motion_that_collides() {
    let dir = tempfile::tempdir().unwrap();
    let size = |amp: &str, out: &str| {
        let out = dir.path().join(out);
        let code = common::armscope(&["size", "--amp-deg", amp, "--duration", "2", "--candidates", "17HS4401,23HS22-2804S,XM540-W270", "--parts-in-urdf", "--out", out.to_str().unwrap()]);
        (code, serde_json::from_str::<Value>(&std::fs::read_to_string(out.join("size.json")).unwrap()).unwrap())
    };
    let (code, folded) = size("90", "folded");
    assert_eq!(code, 1);
    assert_eq!(folded["verified"], Value::Bool(false));
    let c = &folded["collision"];
    assert!(c[2].is_string() && c[3].is_string() && c[1].as_f64().unwrap() >= 0.0, "{c}");
    let (code, tutorial) = size("30", "tutorial");
    assert_eq!((code, tutorial["collision"].is_null()), (0, true));
    // the chosen set's full simulation is checked at every control step as well: no contact, and
    // the closest approach is the one a run with those drives reports
    let simulated = &tutorial["simulated_collisions"][0][1];
    assert!(simulated["first_contact"].is_null() && simulated["pairs_checked"] == 15, "{simulated}");
    // with a floor at −0.2 m (size takes --floor too): the command stays above it in these 2 s,
    // but the chosen drives' arm sags through it — the full simulation's check finds it, the sizing
    // is no valid one, and a run of the written motor file with the same flags meets the floor at
    // the same step
    let out = dir.path().join("floor");
    let code = common::armscope(&["size", "--floor", "-0.2", "--duration", "2", "--candidates", "17HS4401,23HS22-2804S,XM540-W270", "--parts-in-urdf", "--out", out.to_str().unwrap()]);
    let floor: Value = serde_json::from_str(&std::fs::read_to_string(out.join("size.json")).unwrap()).unwrap();
    let simulated = &floor["simulated_collisions"][0][1]["first_contact"];
    assert_eq!((code, floor["verified"].as_bool(), floor["collision"].is_null()), (1, Some(false), true), "{floor}");
    assert_eq!((simulated[1].as_str(), simulated[2].as_str()), (Some("tool_link"), Some("floor")), "{simulated}");
    assert!(std::fs::read_to_string(out.join("size.md")).unwrap().contains("**The simulated arm collides**"));
    let summary = dir.path().join("run.json");
    let motors = out.join("motors.toml");
    assert_eq!(common::armscope(&["run", "--quiet", "--motors", motors.to_str().unwrap(), "--duration", "2", "--auto-tune", "--floor", "-0.2", "--summary-json", summary.to_str().unwrap()]), 0);
    let run: Value = serde_json::from_str(&std::fs::read_to_string(&summary).unwrap()).unwrap();
    assert_eq!(run["summary"]["collisions"]["first_contact"], *simulated, "the run of the chosen motors");
}

/// A bad scene file stops `run` and `trajectory` before anything is written: exit 2 and one line
/// naming the file, the object and the field.
#[test]
fn a_bad_scene_file_is_one_line_naming_file_and_field() {
    let dir = tempfile::tempdir().unwrap();
    let scene = dir.path().join("scene.toml");
    std::fs::write(&scene, "[[object]]\nname = \"wall\"\nshape = \"box\"\nsize = [0.1, 2.0]\n").unwrap();
    for args in [vec!["run", "--no-rrd", "--no-mcap", "--quiet", "--duration", "0.1"], vec!["trajectory", "circle", "--out"]] {
        let mut args: Vec<String> = args.into_iter().map(String::from).collect();
        if args[0] == "trajectory" {
            args.push(dir.path().join("c").display().to_string());
        }
        let out = std::process::Command::new(env!("CARGO_BIN_EXE_armscope")).args(&args).args(["--scene", scene.to_str().unwrap()]).output().unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{err}");
        let line = err.lines().find(|l| l.contains("error")).unwrap_or_default();
        assert!(line.contains("scene.toml") && line.contains("object 'wall'") && line.contains("field 'size'"), "{err}");
        assert!(!dir.path().join("c.csv").exists(), "nothing written");
    }
}

/// The recordings show the checks (the table scene of the test above, 3 s): in the `.rrd` a
/// `collisions/in_contact` row per step whose steps with contact, sum of pairs and first contact
/// are the summary's; the tool's and the table's shapes red from the first contact on (their
/// own colour before); a `collisions/events` log. In the `.mcap`, decoded through the schema it
/// carries, a `/collisions` message per step equal to the `.rrd`'s rows, `/collisions/contacts`
/// updates each replacing the whole set (first at the first contact: the tool and the table), and
/// the table drawn with the robot's geometry.
#[test]
fn recordings_show_what_is_in_contact_and_when() {
    use prost::Message as _;
    let dir = tempfile::tempdir().unwrap();
    let scene = dir.path().join("scene.toml");
    std::fs::write(&scene, "[[object]]\nname = \"table\"\nshape = \"box\"\nsize = [2.0, 2.0, 0.3]\nxyz = [0.0, 0.0, -0.3]\n\n[payload]\nshape = \"sphere\"\nradius = 0.04\nxyz = [0.1, 0.0, 0.0]\n").unwrap();
    let (rrd, mcap, summary) = (dir.path().join("c.rrd"), dir.path().join("c.mcap"), dir.path().join("c.json"));
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_armscope"))
        .args(["run", "--quiet", "--duration", "3", "--scene", scene.to_str().unwrap(), "--rrd", rrd.to_str().unwrap(), "--mcap", mcap.to_str().unwrap(), "--summary-json", summary.to_str().unwrap()])
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let s: Value = serde_json::from_str(&std::fs::read_to_string(&summary).unwrap()).unwrap();
    let c = &s["summary"]["collisions"];
    let first = c["first_contact"][0].as_f64().unwrap();
    let steps_in_contact = c["steps_in_contact"].as_u64().unwrap();
    let pair_steps: u64 = c["pairs"].as_array().unwrap().iter().map(|p| p["steps_in_contact"].as_u64().unwrap()).sum();
    let steps = 3001;

    let rrd = common::rrd::Rrd::open(&rrd);
    assert!(rrd.verify_errors.is_empty(), "{:?}", rrd.verify_errors);
    let count = rrd.series("/collisions/in_contact");
    assert_eq!(count.len(), steps, "a row per step");
    assert_eq!(count.iter().filter(|r| r.1[0] > 0.0).count() as u64, steps_in_contact);
    assert_eq!(count.iter().map(|r| r.1[0]).sum::<f64>() as u64, pair_steps);
    // (the .rrd keeps times in whole nanoseconds)
    let at = |t: f64| (t - first).abs() < 1e-9;
    assert!(at(count.iter().find(|r| r.1[0] > 0.0).unwrap().0), "the first step with a contact is the summary's");
    let min = rrd.series("/collisions/min_distance");
    assert!(min.iter().find(|r| at(r.0)).unwrap().1[0] <= 0.0);
    let red = f64::from(0xEB1E1EFFu32);
    for (entity, component) in [("/world/robot/tool_link/visual_0", "Boxes3D:colors"), ("/world/robot/tool_link/payload", "Ellipsoids3D:colors"), ("/world/scene/table", "Boxes3D:colors")] {
        let colours = rrd.component(entity, component);
        assert_eq!(colours[0].0, 0.0, "{entity}: its own colour from the start");
        assert_ne!(colours[0].1[0], red, "{entity}");
        let at_first = colours.iter().rev().find(|r| r.0 <= first + 1e-9).unwrap();
        assert_eq!(at_first.1[0], red, "{entity}: red at the first contact, t = {first}");
        assert!(colours.windows(2).all(|w| w[0].1 != w[1].1), "{entity}: logged at the changes only");
    }
    assert!(rrd.entities().contains_key("/collisions/events"));

    let bytes = std::fs::read(&mcap).unwrap();
    let (mut states, mut times, mut contacts, mut geometry) = (Vec::new(), Vec::new(), Vec::new(), None);
    for m in mcap::MessageStream::new(&bytes).unwrap().map(|m| m.unwrap()) {
        match m.channel.topic.as_str() {
            "/collisions" => {
                times.push(m.log_time);
                let schema = m.channel.schema.clone().unwrap();
                let pool = prost_reflect::DescriptorPool::decode(&schema.data[..]).unwrap();
                states.push(prost_reflect::DynamicMessage::decode(pool.get_message_by_name(&schema.name).unwrap(), &m.data[..]).unwrap());
            }
            "/collisions/contacts" => contacts.push((m.log_time, foxglove::messages::SceneUpdate::decode(&m.data[..]).unwrap())),
            "/robot/geometry" if geometry.is_none() => geometry = Some(foxglove::messages::SceneUpdate::decode(&m.data[..]).unwrap()),
            _ => {}
        }
    }
    assert_eq!(states.len(), steps);
    for (state, row) in states.iter().zip(&count) {
        assert!((state.get_field_by_name("time").unwrap().as_f64().unwrap() - row.0).abs() < 1e-9);
        assert_eq!(state.get_field_by_name("in_contact").unwrap().as_u32(), Some(row.1[0] as u32));
    }
    let (first_time, first_update) = &contacts[0];
    let k = count.iter().position(|r| at(r.0)).unwrap();
    assert_eq!(*first_time, times[k], "the first contacts update at the first contact's step");
    assert_eq!(first_update.deletions[0].r#type, foxglove::messages::scene_entity_deletion::Type::All as i32, "each update replaces the set");
    let ids: Vec<&str> = first_update.entities.iter().map(|e| e.id.as_str()).collect();
    assert!(ids.contains(&"contact-tool_link") && ids.contains(&"contact-scene-table"), "{ids:?}");
    assert!(geometry.unwrap().entities.iter().any(|e| e.id == "scene-table" && e.cubes.len() == 1), "the table drawn");
}

/// Checks that remember what they measured skip pairs that cannot matter; a run's checks measure a
/// pair only when the flags need it (`CollisionData::for_run`: in contact, nearer than its closest
/// approach so far, or the step's nearest). Yet both flag what a check that knows nothing of earlier
/// states flags (a new `CollisionData` at every step, every pair within 5 cm measured), step by step
/// along a fast wave that brings links into contact with each other, a floor, a table and a post:
/// the pairs in contact with their depths, the step's smallest distance, and the run's summary
/// (first contact, steps in contact, each pair's closest approach and its time). Boxes against
/// boxes, a floor and a cylinder (the box model, its payload a ball), and STL meshes against each
/// other, a box and a cylinder (the SmallRobotArm mesh model). Boxes agree to the last bit; a mesh's
/// distance through its hull is taken when GJK's closest points are within `hull::ON_SURFACE` =
/// 1e-9 m of its lower bound, so two answers from different starting points are within 2e-9 m
/// (1.1e-9 m seen, a mesh against the cylinder).
#[test]
fn a_run_measures_less_but_flags_what_every_pair_would() {
    use armscope::collision::{CollisionData, RunLog, StateCollisions, check_state};
    let dir = tempfile::tempdir().unwrap();
    let scene = dir.path().join("scene.toml");
    std::fs::write(
        &scene,
        "floor = -0.2\n[[object]]\nname = \"table\"\nshape = \"box\"\nsize = [0.4, 1.2, 0.04]\nxyz = [0.35, 0.0, 0.12]\n\n[[object]]\nname = \"post\"\nshape = \"cylinder\"\nradius = 0.03\nlength = 0.5\nxyz = [0.2, 0.15, 0.25]\n\n[payload]\nshape = \"sphere\"\nradius = 0.03\nxyz = [0.07, 0.0, 0.0]\n",
    )
    .unwrap();
    let scene = armscope::collision::Scene::load(&scene).unwrap();
    let meshes = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("assets/smallrobotarm/smallrobotarm.urdf");
    let free = armscope::collision::Scene::default();
    // (model, scene, amplitude rad, ω rad/s): the last, the box model's own pairs on a slower wave,
    // has stretches with nothing within 5 cm (the checks skip whole steps there) and without
    for (urdf, scene, amplitude, omega) in [(common::box_urdf(), &scene, 1.6, 2.0), (meshes, &scene, 1.2, 2.0), (common::box_urdf(), &free, 0.9, 1.0)] {
        let model = load_urdf(&urdf).unwrap();
        let c = Collisions::new(&model, None, scene).unwrap();
        let mut data = armscope::dynamics::Data::new(&model);
        let (mut run, mut every) = (CollisionData::for_run(&c.shapes), CollisionData::new(&c.shapes));
        let (mut run_state, mut every_state, mut fresh_state) = (StateCollisions::default(), StateCollisions::default(), StateCollisions::default());
        let (mut run_log, mut fresh_log) = (RunLog::new(&c), RunLog::new(&c));
        let (mut contacts, mut near, mut clear_steps) = (0, 0, 0);
        for k in 0..6000 {
            let t = k as f64 * 1e-3;
            let q: Vec<f64> = (0..model.dof()).map(|i| amplitude * (omega * t + i as f64 * std::f64::consts::FRAC_PI_3).sin()).collect();
            armscope::dynamics::forward_kinematics(&model, &mut data, &q);
            check_state(&model, &c.shapes, &c.pairs, &c.world, &mut run, &data.body_pose, 0.05, &mut run_state);
            check_state(&model, &c.shapes, &c.pairs, &c.world, &mut every, &data.body_pose, 0.05, &mut every_state);
            check_state(&model, &c.shapes, &c.pairs, &c.world, &mut CollisionData::new(&c.shapes), &data.body_pose, 0.05, &mut fresh_state);
            run_log.record(&model, &c, t, &run_state);
            fresh_log.record(&model, &c, t, &fresh_state);
            let within = |s: &StateCollisions| s.close.iter().map(|p| ((p.a, format!("{:?}", p.b)), p.distance)).collect::<std::collections::BTreeMap<_, _>>();
            let (every_pairs, fresh_pairs) = (within(&every_state), within(&fresh_state));
            assert!(every_pairs.keys().eq(fresh_pairs.keys()) && every_pairs.values().zip(fresh_pairs.values()).all(|(x, y)| (x - y).abs() <= 2e-9), "{}: t = {t}: {every_pairs:?} vs {fresh_pairs:?}", urdf.display());
            // (nearest first; pairs at the same distance in either order)
            let touching = |s: &StateCollisions| {
                let mut pairs: Vec<_> = s.colliding().map(|p| (p.a, p.b, p.distance)).collect();
                pairs.sort_by_key(|p| (p.0, format!("{:?}", p.1)));
                pairs
            };
            let (a, b) = (touching(&run_state), touching(&fresh_state));
            assert_eq!(a.len(), b.len(), "{}: t = {t}: {a:?} vs {b:?}", urdf.display());
            for (x, y) in a.iter().zip(&b) {
                assert!(x.0 == y.0 && x.1 == y.1 && (x.2 - y.2).abs() <= 2e-9, "{}: t = {t}: {a:?} vs {b:?}", urdf.display());
            }
            match (run_state.min_distance(), fresh_state.min_distance()) {
                (Some(x), Some(y)) => assert!((x - y).abs() <= 2e-9, "{}: t = {t}: nearest {x} vs {y}", urdf.display()),
                (x, y) => assert_eq!(x, y, "{}: t = {t}", urdf.display()),
            }
            assert!(run_state.close.len() <= fresh_state.close.len());
            contacts += b.len();
            near += fresh_state.close.len();
            clear_steps += fresh_state.close.is_empty() as usize;
        }
        let (a, b) = (run_log.finish(), fresh_log.finish());
        assert_eq!((a.first_contact.clone(), a.steps_in_contact, a.pairs.len()), (b.first_contact.clone(), b.steps_in_contact, b.pairs.len()), "{}", urdf.display());
        for (x, y) in a.pairs.iter().zip(&b.pairs) {
            assert!(x.link1 == y.link1 && x.link2 == y.link2 && x.steps_in_contact == y.steps_in_contact && x.closest_at == y.closest_at && (x.closest - y.closest).abs() <= 2e-9, "{}: {x:?} vs {y:?}", urdf.display());
        }
        // the waves bring several pairs into contact and more within 5 cm, or in and out of 5 cm
        let touched: Vec<_> = b.pairs.iter().filter(|p| p.steps_in_contact > 0).map(|p| (p.link1.clone(), p.link2.clone())).collect();
        let what = format!("{}: {contacts} pair-steps in contact, {near} within 5 cm, {clear_steps} steps with none, touched {touched:?}", urdf.display());
        if std::ptr::eq(scene, &free) {
            assert!(clear_steps > 1000 && 6000 - clear_steps > 1000, "{what}");
        } else {
            assert!(contacts > 500 && near > contacts + 1000 && touched.len() >= 3, "{what}");
        }
    }
}
