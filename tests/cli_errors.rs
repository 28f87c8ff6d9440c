//! Every bad input is one line on stderr that names the file and the link, joint or flag, with
//! exit code 2, and no panic.

mod common;

use std::process::Command;

const GOOD_LINK: &str = r#"<inertial><mass value="1"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial>"#;

/// A two-link arm with `{L1}` / `{J1}` placeholders for the parts a case breaks.
fn arm(link1_inertial: &str, joint1: &str) -> String {
    format!(
        r#"<robot name="t"><link name="world"/><link name="a">{GOOD_LINK}</link><link name="b">{link1_inertial}</link>
<joint name="weld" type="fixed"><parent link="world"/><child link="a"/></joint>
{joint1}
</robot>"#
    )
}

fn revolute(extra: &str) -> String {
    format!(r#"<joint name="J1" type="revolute"><parent link="a"/><child link="b"/><axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="5" velocity="1"/>{extra}</joint>"#)
}

fn run_with_urdf(text: &str, extra: &[&str]) -> (i32, String) {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("bad.urdf");
    std::fs::write(&path, text).unwrap();
    let mut args = vec!["run", "--quiet", "--no-rrd", "--no-mcap", "--duration", "0.01", "--urdf", path.to_str().unwrap()];
    args.extend_from_slice(extra);
    run(&args)
}

fn run(args: &[&str]) -> (i32, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_armscope")).args(args).output().unwrap();
    (out.status.code().unwrap_or(-1), String::from_utf8_lossy(&out.stderr).to_string())
}

#[track_caller]
fn assert_error(result: (i32, String), code: i32, needles: &[&str]) {
    let (status, stderr) = result;
    assert_eq!(status, code, "exit code; stderr: {stderr}");
    let lines: Vec<&str> = stderr.lines().filter(|l| !l.contains("notice:")).collect();
    assert_eq!(lines.len(), 1, "one line of error: {stderr:?}");
    assert!(!stderr.contains("panicked"), "{stderr}");
    for n in needles {
        assert!(lines[0].contains(n), "{n:?} not in {:?}", lines[0]);
    }
}

#[test]
fn missing_file() {
    assert_error(run(&["run", "--urdf", "/nonexistent/arm.urdf"]), 2, &["/nonexistent/arm.urdf", "cannot read"]);
}

#[test]
fn malformed_xml() {
    assert_error(run_with_urdf("<robot name='x'><link name='a'>", &[]), 2, &["bad.urdf", "malformed XML"]);
}

#[test]
fn unknown_parent_and_child() {
    let j = r#"<joint name="J1" type="revolute"><parent link="nope"/><child link="b"/><axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="5" velocity="1"/></joint>"#;
    assert_error(run_with_urdf(&arm(GOOD_LINK, j), &[]), 2, &["bad.urdf", "joint 'J1'", "unknown parent link 'nope'"]);
    let j = r#"<joint name="J1" type="revolute"><parent link="a"/><child link="ghost"/><axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="5" velocity="1"/></joint>"#;
    assert_error(run_with_urdf(&arm(GOOD_LINK, j), &[]), 2, &["joint 'J1'", "unknown child link 'ghost'"]);
}

#[test]
fn cycle() {
    let j = format!(
        "{}{}",
        revolute(""),
        r#"<link name="c">GOOD</link><joint name="J2" type="revolute"><parent link="b"/><child link="c"/><axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="5" velocity="1"/></joint>
<joint name="J3" type="revolute"><parent link="c"/><child link="b"/><axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="5" velocity="1"/></joint>"#
            .replace("GOOD", GOOD_LINK)
    );
    // b gets two parents (J1 and J3): caught as such
    assert_error(run_with_urdf(&arm(GOOD_LINK, &j), &[]), 2, &["link 'b' has two parent joints"]);
    // a pure cycle detached from the root
    let text = format!(
        r#"<robot name="t"><link name="world"/><link name="p">{GOOD_LINK}</link><link name="q">{GOOD_LINK}</link>
<joint name="A" type="revolute"><parent link="p"/><child link="q"/><axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="5" velocity="1"/></joint>
<joint name="B" type="revolute"><parent link="q"/><child link="p"/><axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="5" velocity="1"/></joint></robot>"#
    );
    assert_error(run_with_urdf(&text, &[]), 2, &["bad.urdf", "cycle"]);
}

#[test]
fn duplicate_names() {
    let text = arm(GOOD_LINK, &revolute("")).replace(r#"<link name="b">"#, r#"<link name="a">"#);
    assert_error(run_with_urdf(&text, &[]), 2, &["duplicate link name 'a'"]);
    let text = arm(GOOD_LINK, &format!("{}{}", revolute(""), revolute("").replace("\"b\"", "\"a\"")));
    assert_error(run_with_urdf(&text, &[]), 2, &["duplicate joint name 'J1'"]);
}

#[test]
fn zero_and_negative_mass() {
    let massless = r#"<inertial><mass value="0"/><inertia ixx="0" ixy="0" ixz="0" iyy="0" iyz="0" izz="0"/></inertial>"#;
    // a moving joint whose whole subtree has no inertia about its motion: the joint and the link to fix
    assert_error(run_with_urdf(&arm(massless, &revolute("")), &[]), 2, &["link 'b'", "joint 'J1'", "moves nothing"]);
    let negative = GOOD_LINK.replace(r#"value="1""#, r#"value="-2""#);
    assert_error(run_with_urdf(&arm(&negative, &revolute("")), &[]), 2, &["link 'b'", "mass -2 is negative"]);
}

#[test]
fn inertia_not_positive_definite_or_breaking_triangle_inequality_with_strict_inertia() {
    // the error Drake gives, with --strict-inertia; without it a notice (tests/any_arm.rs)
    let singular = GOOD_LINK.replace(r#"izz="0.01""#, r#"izz="0""#);
    assert_error(run_with_urdf(&arm(&singular, &revolute("")), &["--strict-inertia"]), 2, &["link 'b'", "not positive definite"]);
    let triangle = GOOD_LINK.replace(r#"izz="0.01""#, r#"izz="0.05""#);
    assert_error(run_with_urdf(&arm(&triangle, &revolute("")), &["--strict-inertia"]), 2, &["link 'b'", "triangle inequality"]);
    let (code, stderr) = run_with_urdf(&arm(&triangle, &revolute("")), &[]);
    assert_eq!(code, 0, "{stderr}");
    assert!(stderr.lines().any(|l| l.starts_with("armscope: notice: link 'b'") && l.contains("triangle inequality")), "{stderr}");
}

#[test]
fn nan_and_infinite_numbers() {
    let nan = GOOD_LINK.replace(r#"ixx="0.01""#, r#"ixx="nan""#);
    assert_error(run_with_urdf(&arm(&nan, &revolute("")), &[]), 2, &["link 'b'", "inertia", "NaN"]);
    let inf = revolute("").replace(r#"<axis xyz="0 0 1"/>"#, r#"<axis xyz="0 0 1"/><origin xyz="inf 0 0"/>"#);
    assert_error(run_with_urdf(&arm(GOOD_LINK, &inf), &[]), 2, &["joint 'J1'", "origin", "inf"]);
}

#[test]
fn zero_axis() {
    let j = revolute("").replace(r#"<axis xyz="0 0 1"/>"#, r#"<axis xyz="0 0 0"/>"#);
    assert_error(run_with_urdf(&arm(GOOD_LINK, &j), &[]), 2, &["joint 'J1'", "axis is zero"]);
}

#[test]
fn floating_and_planar_are_not_supported() {
    for kind in ["floating", "planar"] {
        let j = revolute("").replace(r#"type="revolute""#, &format!(r#"type="{kind}""#));
        assert_error(run_with_urdf(&arm(GOOD_LINK, &j), &[]), 2, &["joint 'J1'", kind, "not supported"]);
    }
}

#[test]
fn a_mimic_of_a_missing_or_fixed_joint_or_a_cycle_is_an_error_naming_both_joints() {
    let mimic = |name: &str, child: &str, target: &str| {
        format!(
            r#"<link name="{child}">{GOOD_LINK}</link><joint name="{name}" type="revolute"><parent link="b"/><child link="{child}"/><axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="5" velocity="1"/><mimic joint="{target}"/></joint>"#
        )
    };
    let j = format!("{}{}", revolute(""), mimic("M", "c", "J9"));
    assert_error(run_with_urdf(&arm(GOOD_LINK, &j), &[]), 2, &["joint 'M'", "<mimic joint='J9'>", "does not have"]);
    let fixed = r#"<link name="f"/><joint name="F" type="fixed"><parent link="b"/><child link="f"/></joint>"#;
    let j = format!("{}{}{fixed}", revolute(""), mimic("M", "c", "F"));
    assert_error(run_with_urdf(&arm(GOOD_LINK, &j), &[]), 2, &["joint 'M'", "<mimic joint='F'>", "fixed joint"]);
    let j = format!("{}{}{}", revolute(""), mimic("M", "c", "N"), mimic("N", "d", "M"));
    assert_error(run_with_urdf(&arm(GOOD_LINK, &j), &[]), 2, &["<mimic joint=", "cycle of mimic joints"]);
}

#[test]
fn unwelded_root_is_welded_with_a_notice() {
    let text = format!(
        r#"<robot name="t"><link name="base">{GOOD_LINK}</link><link name="b">{GOOD_LINK}</link>
<joint name="J1" type="revolute"><parent link="base"/><child link="b"/><origin xyz="0.1 0 0"/><axis xyz="0 1 0"/><limit lower="-1" upper="1" effort="50" velocity="1"/></joint></robot>"#
    );
    let (code, stderr) = run_with_urdf(&text, &[]);
    assert_eq!(code, 0, "{stderr}");
    assert!(stderr.contains("notice: root link 'base' is not attached to 'world'; welding it"), "{stderr}");
}

#[test]
fn bad_flags_name_the_flag() {
    assert_error(run(&["run", "--kp", "1,2,3"]), 2, &["--kp", "expected 1 value or 6", "got 3"]);
    assert_error(run(&["run", "--test-joint", "J9"]), 2, &["--test-joint", "no moving joint 'J9'", "smallrobot_arm.urdf"]);
    assert_error(run(&["run", "--test-joint", "7"]), 2, &["--test-joint", "out of range"]);
    assert_error(run(&["run", "--dt", "0"]), 2, &["--dt", "positive"]);
    assert_error(run(&["run", "--duration", "abc"]), 2, &["--duration"]);
    assert_error(run(&["run", "--time-step", "0.0003"]), 2, &["--time-step", "whole number"]);
    assert_error(run(&["run", "--integrator", "discrete", "--time-step", "0"]), 2, &["--time-step", "continuous"]);
    assert_error(run(&["run", "--no-such-flag"]), 2, &["--no-such-flag"]);
    assert_error(run(&["run", "--tool", "nowhere"]), 2, &["--tool", "nowhere"]);
}

/// A payload so heavy that the joints' own inertias vanish beside it in rounding: the plant could
/// not be solved (before, the run diverged at its first step with a hint to try the continuous
/// plant). The flag is named, with the joint whose inertia is lost; no recording is started.
#[test]
fn a_payload_that_swamps_the_arm_in_rounding_is_an_error_naming_the_flag() {
    let dir = tempfile::tempdir().unwrap();
    let rrd = dir.path().join("p.rrd");
    let (status, stderr) = run(&["run", "--quiet", "--no-mcap", "--duration", "0.01", "--payload", "1e16", "--rrd", rrd.to_str().unwrap()]);
    assert_error((status, stderr), 2, &["--payload", "1e16 kg", "joint 'J3'", "the mass matrix is singular"]);
    assert!(!rrd.exists(), "no recording of a run that never started");
}

/// The same check on a URDF's own numbers (a 1e308 kg tool whose inertial origin is lost, see
/// urdf_fuzz.rs) names the file and the joint, in `run` and in `model`.
#[test]
fn a_urdf_whose_mass_matrix_is_singular_in_rounding_is_an_error_naming_the_joint() {
    let text = std::fs::read_to_string(common::box_urdf()).unwrap();
    let tool = "<origin xyz=\"0.02 0 0\" rpy=\"0 0 0\"/>\n      <mass value=\"0.05\"/>";
    assert!(text.contains(tool), "the box model's tool link changed");
    let heavy = text.replace(tool, "<onanrigin xyz=\"0.02 0 0\" rpy=\"0 0 0\"/>\n      <mass value=\"1e308\"/>");
    assert_error(run_with_urdf(&heavy, &[]), 2, &["bad.urdf", "joint 'J3'", "the mass matrix is singular"]);
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("heavy.urdf");
    std::fs::write(&path, &heavy).unwrap();
    assert_error(run(&["model", "--urdf", path.to_str().unwrap()]), 2, &["heavy.urdf", "joint 'J3'", "the mass matrix is singular"]);
}
