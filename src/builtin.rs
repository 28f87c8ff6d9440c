//! Files built into the binary, so that `cargo install` gives a tool that runs its own defaults in
//! any folder: the tutorial's box model, its batch manifest, the motor catalogue and motor files. A default path that exists on disk
//! (the repository's own `assets/`) is read from disk; where it does not, the built-in copy is used.

use std::path::Path;

pub const DEFAULT_URDF: &str = "assets/smallrobot_arm.urdf";
pub const DEFAULT_MANIFEST: &str = "assets/experiments/tutorial.toml";
pub const DEFAULT_CATALOGUE: &str = "assets/motors/catalogue.toml";

const FILES: [(&str, &str); 6] = [
    (DEFAULT_URDF, include_str!("../assets/smallrobot_arm.urdf")),
    (DEFAULT_MANIFEST, include_str!("../assets/experiments/tutorial.toml")),
    (DEFAULT_CATALOGUE, include_str!("../assets/motors/catalogue.toml")),
    ("assets/motors/tutorial.toml", include_str!("../assets/motors/tutorial.toml")),
    ("assets/motors/smallrobotarm.toml", include_str!("../assets/motors/smallrobotarm.toml")),
    ("assets/motors/so100.toml", include_str!("../assets/motors/so100.toml")),
];

/// The text of `path`: the file's, or the built-in copy when `path` is a default that is not on disk.
pub fn read_to_string(path: &Path) -> std::io::Result<String> {
    match std::fs::read_to_string(path) {
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => builtin(path).map(str::to_string).ok_or(e),
        other => other,
    }
}

/// The built-in copy of a default file, by its default path.
pub fn builtin(path: &Path) -> Option<&'static str> {
    FILES.iter().find(|(name, _)| Path::new(name) == path).map(|(_, text)| *text)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_built_in_copies_are_the_repository_files() {
        for (name, text) in FILES {
            let on_disk = std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join(name)).unwrap();
            assert_eq!(on_disk, text, "{name}");
        }
    }

    #[test]
    fn a_missing_default_falls_back_to_the_built_in_copy_and_other_paths_do_not() {
        let dir = tempfile::tempdir().unwrap();
        let cwd = std::env::current_dir().unwrap();
        assert!(builtin(Path::new(DEFAULT_URDF)).is_some());
        assert!(read_to_string(&dir.path().join("nothing.urdf")).is_err());
        assert!(builtin(&cwd.join(DEFAULT_URDF)).is_none(), "only the default path as given");
    }
}
