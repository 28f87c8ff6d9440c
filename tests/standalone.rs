//! The binary needs nothing from the repository: its default model and the tutorial's batch
//! manifest are built in, so `cargo install` gives a tool that runs in any folder.

use std::process::Command;

fn armscope_in(dir: &std::path::Path, args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_armscope")).args(args).current_dir(dir).output().unwrap()
}

#[test]
fn run_in_a_folder_that_is_not_the_repository_writes_its_recordings_there() {
    let dir = tempfile::tempdir().unwrap();
    let out = armscope_in(dir.path(), &["run", "--duration", "1", "--quiet", "--name", "default"]);
    assert_eq!(out.status.code(), Some(0), "{}", String::from_utf8_lossy(&out.stderr));
    for file in ["default.rrd", "default.mcap", "default.layout.json"] {
        let len = std::fs::metadata(dir.path().join("recordings").join(file)).map(|m| m.len()).unwrap_or(0);
        assert!(len > 0, "recordings/{file} written");
    }
    // the same model as the repository's file
    let mcap = std::fs::read(dir.path().join("recordings/default.mcap")).unwrap();
    let description = mcap::MessageStream::new(&mcap).unwrap().map(|m| m.unwrap()).find(|m| m.channel.topic == "/robot_description").unwrap();
    let urdf = std::fs::read_to_string(std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("assets/smallrobot_arm.urdf")).unwrap();
    assert_eq!(armscope::recorder::decode_robot_description(&description.data), Some(urdf.as_str()));
}

#[test]
fn the_tutorial_batch_runs_in_any_folder() {
    let dir = tempfile::tempdir().unwrap();
    // one experiment of the built-in manifest (shard 1 of 13: "static", 10 s)
    let out = armscope_in(dir.path(), &["batch", "--shard", "1/13", "--no-compare", "--jobs", "1"]);
    assert_eq!(out.status.code(), Some(0), "{}", String::from_utf8_lossy(&out.stderr));
    let summary = std::fs::read_to_string(dir.path().join("recordings/tutorial/summary.shard-1-of-13.json")).expect("the shard's summary");
    assert!(summary.contains("\"static\""), "{summary}");
}
