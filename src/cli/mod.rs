//! The command line: a thin layer that turns flags into library calls, one file per subcommand.

mod analyze;
mod batch;
mod catalogue;
mod compare;
mod envelope;
mod identify;
mod identify_arm;
mod model;
mod reference;
mod replay;
mod run;
mod size;
mod testbench;
mod trajectory;

pub use analyze::{AnalyzeArgs, analyze};
pub use batch::{BatchAction, BatchArgs, batch};
pub use catalogue::{CatalogueArgs, catalogue};
pub use compare::{CompareArgs, compare};
pub use envelope::{EnvelopeArgs, envelope};
pub use identify::{IdentifyArgs, identify};
pub use model::{ModelArgs, model};
pub use reference::{CompletionsArgs, ReferenceArgs, commands, completions, long_help, markdown as reference_markdown, reference};
pub use replay::{ReplayArgs, replay, trace_path};
pub use crate::flags::{GainArgs, MotorArgs, RunArgs, WaveArgs};
pub use run::{default_run_name, run};
pub use size::{SizeArgs, parse_ratios, size};
pub use testbench::{TestbenchArgs, read_logs, read_logs_for, read_params, servo_of, testbench};
pub use trajectory::{TrajectoryArgs, trajectory};

use crate::config::{IntegratorKind, RunConfig};
use crate::error::Error;
use crate::experiment::Experiment;
use crate::recorder::LiveViewer;
use crate::runner::{Outputs, run_experiment};
use crate::summary::RunStatus;
use clap::{Args, Parser, Subcommand};
use std::ffi::OsString;
use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, Ordering};

#[derive(Parser, Debug)]
#[command(name = "armscope", version, about = "Simulate a robot arm with real rigid-body dynamics and record every experiment")]
pub struct Cli {
    #[command(subcommand)]
    pub command: Command,
}

#[derive(Subcommand, Debug)]
pub enum Command {
    /// Run one experiment: the tutorial's PD + gravity-compensation controller on the arm.
    Run(RunArgs),
    /// Run many experiments from a TOML manifest, in parallel, into recordings/BATCH/.
    Batch(BatchArgs),
    /// Build one comparison recording (.rrd) from the .mcap files of finished runs.
    Compare(CompareArgs),
    /// Draw a shape with the tool: inverse kinematics into a joint schedule for `run --trajectory`.
    Trajectory(TrajectoryArgs),
    /// Is the sampled control loop stable? Spectral radius, the joints that drive it, stable dt and gains.
    Analyze(AnalyzeArgs),
    /// How fast can the arm go: sweep wave frequency × amplitude, map where each motor runs out of torque.
    Envelope(EnvelopeArgs),
    /// What armscope made of a URDF: joints, limits, motors, notices; with --states, the dynamics
    /// (M, τ_g, C·v, q̈, link poses) at given states as JSON, to compare with other libraries.
    Model(ModelArgs),
    /// Which motor and which gear ratio per joint for a motion: ranks a catalogue over a range of
    /// ratios, verifies the choice in simulation, writes a motor file for `run --motors`.
    Size(SizeArgs),
    /// The motors and reductions to choose from, each with its source; --check FILE validates yours.
    Catalogue(CatalogueArgs),
    /// Replay servo bench logs (BAM's pendulum JSON) against a servo model: position error, PWM, where they part.
    Testbench(TestbenchArgs),
    /// Fit a servo's parameters (BAM's JSON) to bench logs, and check them on held-out logs.
    Identify(IdentifyArgs),
    /// What a real arm's recorded motion took: a LeRobot dataset, ROS 2 bag or CSV into the torque
    /// each joint needed, held against what its motor gives; the episodes that overloaded first.
    Replay(ReplayArgs),
    /// The command reference generated from this command line: one Markdown page, or man pages.
    Reference(ReferenceArgs),
    /// A shell completion script on stdout, e.g. `armscope completions bash > ~/.local/share/bash-completion/completions/armscope`.
    Completions(CompletionsArgs),
}

/// Parse `args` and run; returns the process exit code. Errors are printed as one line.
pub fn main_with_args<I, T>(args: I) -> i32
where
    I: IntoIterator<Item = T>,
    T: Into<OsString> + Clone,
{
    let cli = match Cli::try_parse_from(args) {
        Ok(cli) => cli,
        Err(e) => {
            use clap::error::ErrorKind;
            if matches!(e.kind(), ErrorKind::DisplayHelp | ErrorKind::DisplayVersion | ErrorKind::DisplayHelpOnMissingArgumentOrSubcommand) {
                let _ = e.print();
                return if e.kind() == ErrorKind::DisplayHelpOnMissingArgumentOrSubcommand { 2 } else { 0 };
            }
            eprintln!("armscope: {}", parse_error_line(&e));
            return 2;
        }
    };
    match run_command(cli.command) {
        Ok(code) => code,
        Err(e) => {
            eprintln!("armscope: error: {e}");
            e.exit_code()
        }
    }
}

/// A command-line parse error as one line, without clap's `error: `: its message and the lines
/// that complete it (the arguments a "not provided" names), not the usage and help after them.
pub fn parse_error_line(e: &clap::Error) -> String {
    let rendered = e.render().to_string();
    let message: Vec<&str> = rendered.lines().skip_while(|l| l.trim().is_empty()).take_while(|l| !l.trim().is_empty()).map(str::trim).collect();
    let line = if message.is_empty() { "invalid arguments".to_string() } else { message.join(" ") };
    line.strip_prefix("error: ").map(str::to_string).unwrap_or(line)
}

fn run_command(command: Command) -> Result<i32, Error> {
    match command {
        Command::Run(args) => run(&args),
        Command::Batch(args) => batch(&args),
        Command::Compare(args) => compare(&args),
        Command::Trajectory(args) => trajectory(&args),
        Command::Analyze(args) => analyze(&args),
        Command::Envelope(args) => envelope(&args),
        Command::Model(args) => model(&args),
        Command::Size(args) => size(&args),
        Command::Catalogue(args) => catalogue(&args),
        Command::Testbench(args) => testbench(&args),
        Command::Identify(args) => identify(&args),
        Command::Replay(args) => replay(&args),
        Command::Reference(args) => reference(&args),
        Command::Completions(args) => completions(&args),
    }
}

/// Set by SIGINT (Ctrl-C): the run stops after the current step and finishes its files.
static INTERRUPTED: AtomicBool = AtomicBool::new(false);

/// Ctrl-C sets a flag the simulation loop checks every step (the files are then finished).
pub fn install_interrupt_handler() {
    static INSTALLED: std::sync::Once = std::sync::Once::new();
    INSTALLED.call_once(|| {
        // a second handler cannot be installed (e.g. by an embedding program): then Ctrl-C just kills
        let _ = ctrlc::set_handler(|| INTERRUPTED.store(true, Ordering::SeqCst));
    });
}
