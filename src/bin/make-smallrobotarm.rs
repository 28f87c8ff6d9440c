//! Writes assets/smallrobotarm/ (URDF + STL meshes) from src/meshgen.rs.
fn main() {
    let dir = std::env::args().nth(1).unwrap_or_else(|| "assets/smallrobotarm".into());
    if let Err(e) = armscope::meshgen::write_smallrobotarm(std::path::Path::new(&dir)) {
        eprintln!("make-smallrobotarm: {dir}: {e}");
        std::process::exit(1);
    }
    println!("wrote {dir}/smallrobotarm.urdf and {dir}/meshes/");
}
