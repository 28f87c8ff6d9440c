//! The command reference in the user guide is generated from the command line and equals what the binary
//! prints; completions and man pages generate for every command.

use std::path::Path;
use std::process::Command;

const REFERENCE: &str = "docs/src/reference.md";

fn armscope(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_armscope")).args(args).output().expect("the armscope binary runs")
}

/// The committed page is the one the library generates now: a flag added, renamed or redescribed without
/// regenerating the page fails here.
#[test]
fn the_committed_reference_is_the_generated_one() {
    let committed = std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join(REFERENCE)).expect("docs/src/reference.md exists");
    let generated = armscope::cli::reference_markdown();
    assert!(
        committed == generated,
        "{REFERENCE} is out of date with the command line: regenerate it with `cargo run --release -- reference --markdown {REFERENCE}`"
    );
}

/// Each command's section is byte for byte what `armscope COMMAND --help` prints, for every command and
/// subcommand (the binary itself, not the library's rendering of it).
#[test]
fn every_section_is_what_the_binary_prints_for_help() {
    let committed = std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join(REFERENCE)).unwrap();
    let commands = armscope::cli::commands();
    assert!(commands.len() >= 15, "every command is in the reference: {}", commands.len());
    for (name, _) in &commands {
        let mut args: Vec<&str> = name.split(' ').skip(1).collect();
        args.push("--help");
        let output = armscope(&args);
        assert!(output.status.success(), "{name} --help exits 0");
        let printed = String::from_utf8(output.stdout).unwrap();
        let section = format!("\n## {name}\n\n```text\n{printed}```\n");
        assert!(committed.contains(&section), "the reference's section for `{name}` is not what `{name} --help` prints");
    }
}

#[test]
fn completions_generate_for_bash_zsh_and_fish() {
    for (shell, marker) in [("bash", "complete -F _armscope"), ("zsh", "#compdef armscope"), ("fish", "complete -c armscope")] {
        let output = armscope(&["completions", shell]);
        assert!(output.status.success(), "completions {shell} exits 0");
        let script = String::from_utf8(output.stdout).unwrap();
        assert!(script.contains(marker), "the {shell} script registers itself ({marker})");
        // every command and a flag of each kind is completed
        // (fish names a long flag without its dashes: `-l no-ff`)
        for word in ["run", "size", "replay", "completions", "no-ff", "payload", "motors"] {
            assert!(script.contains(word), "the {shell} script completes {word}");
        }
    }
    let unknown = armscope(&["completions", "tcsh"]);
    assert_eq!(unknown.status.code(), Some(2), "an unknown shell is a usage error");
    let message = String::from_utf8(unknown.stderr).unwrap();
    assert_eq!(message.lines().count(), 1, "one line: {message}");
    assert!(message.contains("tcsh"), "names the value: {message}");
}

#[test]
fn man_pages_generate_for_every_command() {
    let dir = tempfile::tempdir().unwrap();
    let output = armscope(&["reference", "--man", dir.path().to_str().unwrap()]);
    assert!(output.status.success(), "{}", String::from_utf8_lossy(&output.stderr));
    for (name, _) in armscope::cli::commands() {
        let file = dir.path().join(format!("{}.1", name.replace(' ', "-")));
        let page = std::fs::read_to_string(&file).unwrap_or_else(|_| panic!("{} written", file.display()));
        assert!(page.starts_with(".ie") || page.contains(".TH"), "{} is a roff man page", file.display());
        assert!(page.contains(&format!(".TH {}", name.replace(' ', "-").to_uppercase())), "{} has its title", file.display());
    }
}

#[test]
fn reference_without_an_output_is_a_one_line_error() {
    let output = armscope(&["reference"]);
    assert_eq!(output.status.code(), Some(2));
    let message = String::from_utf8(output.stderr).unwrap();
    assert_eq!(message.lines().count(), 1, "{message}");
    assert!(message.contains("--markdown"), "{message}");
}
