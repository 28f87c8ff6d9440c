//! `armscope reference` and `armscope completions`: the command reference generated from the command
//! line itself (one Markdown page of every `--help`, man pages by clap_mangen) and shell completions
//! (clap_complete), so that none of them can drift from what the binary accepts.

use super::*;
use clap::CommandFactory;
use std::fmt::Write as _;

#[derive(Args, Debug)]
pub struct ReferenceArgs {
    /// Write the whole reference as one Markdown page (every command's --help) to FILE; `-` for stdout.
    #[arg(long, value_name = "FILE")]
    pub markdown: Option<PathBuf>,
    /// Write a man page for armscope and each of its commands (armscope.1, armscope-run.1, …) into DIR.
    #[arg(long, value_name = "DIR")]
    pub man: Option<PathBuf>,
}

#[derive(Args, Debug)]
pub struct CompletionsArgs {
    /// The shell to complete in: bash, zsh, fish, elvish or powershell.
    #[arg(value_enum)]
    pub shell: clap_complete::Shell,
}

/// Every command of the command line, the root first, depth first, with its full name
/// (`armscope`, `armscope run`, `armscope batch merge`, …). Help and hidden commands are left out.
pub fn commands() -> Vec<(String, clap::Command)> {
    fn walk(prefix: &str, command: &clap::Command, out: &mut Vec<(String, clap::Command)>) {
        let name = if prefix.is_empty() { command.get_name().to_string() } else { format!("{prefix} {}", command.get_name()) };
        out.push((name.clone(), command.clone()));
        for sub in command.get_subcommands().filter(|s| !s.is_hide_set() && s.get_name() != "help") {
            walk(&name, sub, out);
        }
    }
    let mut root = Cli::command();
    root.build();
    let mut out = Vec::new();
    walk("", &root, &mut out);
    out
}

/// What `armscope … --help` prints for the command with this full name (`armscope run`): the command
/// line parsed with `--help`, as the binary parses it (clap lays out a command without long help
/// compactly, which no render function alone reproduces).
pub fn long_help(full_name: &str) -> Option<String> {
    let args = full_name.split(' ').chain(["--help"]);
    match Cli::try_parse_from(args) {
        Err(e) if e.kind() == clap::error::ErrorKind::DisplayHelp => Some(e.render().to_string()),
        _ => None,
    }
}

/// The command reference as one Markdown page: a contents list, then per command its `--help`.
pub fn markdown() -> String {
    let commands = commands();
    let mut page = String::new();
    page.push_str("# Command reference\n\n");
    page.push_str("Generated from the command line itself (`armscope reference --markdown FILE`); each section is exactly\n");
    page.push_str("what `armscope COMMAND --help` prints. Man pages: `armscope reference --man DIR`. Shell completions:\n");
    page.push_str("`armscope completions bash|zsh|fish`.\n\n");
    for (name, command) in &commands {
        let depth = name.matches(' ').count();
        let about = command.get_about().map(|a| a.to_string()).unwrap_or_default();
        let _ = writeln!(page, "{}- [`{name}`](#{}) — {}", "  ".repeat(depth.saturating_sub(1)), anchor(name), about.lines().next().unwrap_or(""));
    }
    for (name, _) in commands {
        let help = long_help(&name).unwrap_or_default();
        let _ = write!(page, "\n## {name}\n\n```text\n{help}```\n");
    }
    page
}

/// The HTML anchor mdBook gives a heading: lower case, spaces as dashes.
fn anchor(heading: &str) -> String {
    heading.to_lowercase().replace(' ', "-")
}

/// `armscope reference`.
pub fn reference(args: &ReferenceArgs) -> Result<i32, Error> {
    if args.markdown.is_none() && args.man.is_none() {
        return Err(Error::flag("--markdown", "say what to write: --markdown FILE (or - for stdout) and/or --man DIR"));
    }
    if let Some(path) = &args.markdown {
        let page = markdown();
        if path.as_os_str() == "-" {
            write_stdout(page.as_bytes())?;
        } else {
            std::fs::write(path, page).map_err(|e| Error::output(path, e))?;
            eprintln!("armscope: wrote {}", path.display());
        }
    }
    if let Some(dir) = &args.man {
        std::fs::create_dir_all(dir).map_err(|e| Error::output(dir, e))?;
        let commands = commands();
        for (name, command) in &commands {
            let path = dir.join(format!("{}.1", name.replace(' ', "-")));
            let mut bytes = Vec::new();
            // the synopsis names the command by its full name (`armscope batch merge`), set when the root was built
            let page = clap_mangen::Man::new(command.clone()).title(name.replace(' ', "-").to_uppercase());
            page.render(&mut bytes).map_err(|e| Error::output(&path, e))?;
            std::fs::write(&path, bytes).map_err(|e| Error::output(&path, e))?;
        }
        eprintln!("armscope: wrote {} man pages into {} (man -l {}/armscope.1)", commands.len(), dir.display(), dir.display());
    }
    Ok(0)
}

/// `armscope completions SHELL`: the completion script on stdout.
pub fn completions(args: &CompletionsArgs) -> Result<i32, Error> {
    let mut command = Cli::command();
    let mut script = Vec::new();
    clap_complete::generate(args.shell, &mut command, "armscope", &mut script);
    write_stdout(&script)?;
    Ok(0)
}

/// Bytes to stdout; a reader that stops early (`| head`) is not an error of ours.
fn write_stdout(bytes: &[u8]) -> Result<(), Error> {
    use std::io::Write;
    match std::io::stdout().lock().write_all(bytes) {
        Err(e) if e.kind() != std::io::ErrorKind::BrokenPipe => Err(Error::output(std::path::Path::new("stdout"), e)),
        _ => Ok(()),
    }
}
