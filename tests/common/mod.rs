//! Helpers shared by the integration tests.
#![allow(dead_code)]

use std::io::Read;
use std::path::{Path, PathBuf};

pub mod follower;
pub mod lerobot;
pub mod random_tree;
pub mod rrd;

/// A 1 kg bob 0.153 m out along x from a horizontal axis (the sizing tests' load): held level its
/// weight's torque is 1.50 N·m at q = 0, and M = 1e-4 + 0.153² kg·m² about the axis.
pub const LEVEL_PENDULUM: &str = r#"<robot name="level_pendulum">
  <link name="world"/>
  <link name="arm"><inertial><origin xyz="0.153 0 0"/><mass value="1"/>
    <inertia ixx="1e-4" iyy="1e-4" izz="1e-4" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <joint name="lift" type="revolute"><parent link="world"/><child link="arm"/><axis xyz="0 1 0"/>
    <limit lower="-3" upper="3" effort="100" velocity="10"/></joint>
</robot>"#;

pub fn repo() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

pub fn box_urdf() -> PathBuf {
    repo().join("assets/smallrobot_arm.urdf")
}

/// The reference data, copied into `tests/fixtures/reference/` (see its README for where it came from).
pub fn reference(file: &str) -> PathBuf {
    repo().join("tests/fixtures/reference").join(file)
}

/// A parsed CSV: header and rows of numbers (`nan` allowed).
pub struct Table {
    pub header: Vec<String>,
    pub rows: Vec<Vec<f64>>,
}

impl Table {
    pub fn col(&self, name: &str) -> usize {
        self.header.iter().position(|h| h == name).unwrap_or_else(|| panic!("no column {name} in {:?}", self.header))
    }

    pub fn column(&self, name: &str) -> Vec<f64> {
        let c = self.col(name);
        self.rows.iter().map(|r| r[c]).collect()
    }
}

pub fn parse_csv(text: &str) -> Table {
    let mut lines = text.lines().filter(|l| !l.starts_with('#') && !l.trim().is_empty());
    let header: Vec<String> = lines.next().expect("header").split(',').map(|s| s.trim().to_string()).collect();
    let rows = lines
        .map(|l| l.split(',').map(|x| x.trim().parse::<f64>().unwrap_or_else(|_| panic!("bad number {x:?}"))).collect())
        .collect();
    Table { header, rows }
}

pub fn read_csv(path: &Path) -> Table {
    parse_csv(&std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display())))
}

pub fn read_csv_gz(path: &Path) -> Table {
    let file = std::fs::File::open(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let mut text = String::new();
    flate2::read::GzDecoder::new(file).read_to_string(&mut text).expect("gunzip");
    parse_csv(&text)
}

/// Run the CLI in-process; returns the exit code. `run` writes no .rrd/.mcap unless the test asks.
pub fn armscope(args: &[&str]) -> i32 {
    let mut argv = vec!["armscope"];
    argv.extend_from_slice(args);
    if args.first() == Some(&"run") && !args.iter().any(|a| *a == "--rrd" || *a == "--mcap") {
        argv.extend_from_slice(&["--no-rrd", "--no-mcap"]);
    }
    armscope::cli::main_with_args(argv)
}

/// Every `/controller` message of a Foxglove-encoded armscope MCAP, decoded.
pub fn controller_messages(mcap: &Path) -> Vec<armscope::recorder::ControllerTelemetry> {
    let bytes = std::fs::read(mcap).unwrap();
    mcap::MessageStream::new(&bytes)
        .unwrap()
        .map(|m| m.unwrap())
        .filter(|m| m.channel.topic == "/controller")
        .map(|m| <armscope::recorder::ControllerTelemetry as prost::Message>::decode(&m.data[..]).unwrap())
        .collect()
}
