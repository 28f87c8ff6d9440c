//! `armscope identify`: fit a servo's parameters to bench logs and check them on held-out logs.

use super::*;
use crate::actuator::bus_servo::{FrictionModel, firmware};
use crate::identify::{FitOptions, Progress, Space, fit};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use crate::testbench::{BenchLog, ReplayOptions, Step, Supply, mae};

#[derive(Args, Debug)]
pub struct IdentifyArgs {
    /// Training logs (BAM's JSON, processed or raw).
    // (no `conflicts_with = "from"` here or on --actuator: clap waives an arg's `requires = "from"`
    // once something present conflicts with --from; `identify` refuses the mix itself)
    #[arg(required_unless_present = "from", value_name = "LOG.json")]
    pub logs: Vec<PathBuf>,
    /// The servo: xl330, xl320, mx64, mx106, sts3215.
    #[arg(long, value_name = "NAME", required_unless_present = "from")]
    pub actuator: Option<String>,
    #[command(flatten)]
    pub arm: super::identify_arm::ArmArgs,
    /// The friction model to fit (BAM's M1–M6).
    #[arg(long, value_enum, default_value_t = FrictionModel::M6)]
    pub friction_model: FrictionModel,
    /// Where to write the parameters (BAM's JSON; `armscope testbench --servo-params` reads it);
    /// with --from, the motor file (FILE.toml, its servos' parameters beside it in FILE.NAME.json).
    #[arg(long, value_name = "P.json")]
    pub out: PathBuf,
    /// Held-out logs: replayed with the fit, not fitted to.
    #[arg(long, value_name = "LOG.json", num_args = 1..)]
    pub validate: Vec<PathBuf>,
    /// bam: BAM's explicit step (what BAM's files are fitted with); exact: armscope's.
    #[arg(long, value_enum, default_value_t = Step::Bam)]
    pub step: Step,
    /// Exact steps per log row (--step exact).
    #[arg(long, default_value_t = 5)]
    pub substeps: usize,
    /// auto: the header's vin, or the log's input_volts row by row where the two disagree by more than
    /// 10 %; nominal: the header's vin; measured: the logs' input_volts row by row.
    #[arg(long, value_enum, default_value_t = Supply::Auto)]
    pub supply: Supply,
    /// Also fit a resistance on the bridge's supply side (a loss growing with the duty squared; BAM
    /// assumes an ideal supply).
    #[arg(long)]
    pub fit_supply_resistance: bool,
    /// Also fit the largest voltage the servo puts across its motor (BAM assumes duty × supply). Done
    /// by default when the logs' supply is above the highest the servo's vendor allows (the XL330's
    /// 6.0 V).
    #[arg(long, conflicts_with = "no_motor_voltage_limit")]
    pub fit_motor_voltage_limit: bool,
    /// Never fit the motor's voltage cap (not even above the vendor's highest supply).
    #[arg(long)]
    pub no_motor_voltage_limit: bool,
    /// Leave the command delay out (0, as BAM's model has it): by default it is fitted, the time
    /// from a goal's sending to the firmware acting on it (the bus, the register read, the loop's
    /// period).
    #[arg(long)]
    pub no_command_delay: bool,
    /// Start the first search from these parameters (BAM's JSON; by default the search space's
    /// centre).
    #[arg(long, value_name = "P.json")]
    pub start: Option<PathBuf>,
    /// The grid a raw log is resampled to, s.
    #[arg(long, value_name = "SECONDS", default_value_t = crate::testbench::log::DEFAULT_DT)]
    pub dt: f64,
    /// Candidates a generation of the search (CMA-ES's λ; 0: its default for the number of
    /// parameters, 4 + ⌊3 ln n⌋, rounded up to an even number: the same on any machine, so that a
    /// seed gives the same fit on any number of cores).
    #[arg(long, default_value_t = FitOptions::default().population)]
    pub population: usize,
    /// Generations at most of each search on the windowed replay (the first stage; default 200);
    /// with --from, of the search on the episodes (default 60).
    #[arg(long)]
    pub generations: Option<usize>,
    /// Generations at most of the refinement on the free-running replay (the second stage).
    #[arg(long, default_value_t = FitOptions::default().refine_generations)]
    pub refine_generations: usize,
    /// Nelder–Mead iterations a simplex of the polish on the free-running replay (the last stage;
    /// 0: 36 000 log replays' worth, 600 to 1000).
    #[arg(long, default_value_t = FitOptions::default().polish_iterations)]
    pub polish_iterations: usize,
    /// Independent searches of the first stage, from different starts; the best is refined. With
    /// --from: searches from the motor file's parameters, each with its own seed (0: three where the
    /// payload is fitted, else one), the one whose servos hold nearest its kept of those ending within
    /// the recording's reading error of the best.
    #[arg(long, default_value_t = FitOptions::default().searches)]
    pub searches: usize,
    /// The random seed of the global search (the same seed, logs and flags give the same fit).
    #[arg(long, default_value_t = FitOptions::default().seed)]
    pub seed: u64,
    /// Write the fit's numbers (loss, per-log MAE, validation) as JSON.
    #[arg(long, value_name = "PATH")]
    pub summary_json: Option<PathBuf>,
    /// No table on the console.
    #[arg(long, short)]
    pub quiet: bool,
}

#[derive(serde::Serialize)]
struct LogMae {
    log: String,
    mae_rad: f64,
}

#[derive(serde::Serialize)]
struct IdentifySummary {
    actuator: String,
    model: String,
    step: Step,
    supply: Supply,
    evaluations: usize,
    replays: usize,
    replays_stopped: usize,
    seconds: f64,
    train: Vec<LogMae>,
    train_mean_mae_rad: f64,
    validate: Vec<LogMae>,
    validate_mean_mae_rad: Option<f64>,
    params: serde_json::Value,
}

fn maes(logs: &[BenchLog], params: &crate::actuator::bus_servo::ServoParams, options: &ReplayOptions) -> Vec<LogMae> {
    use rayon::prelude::*;
    logs.par_iter().map(|l| LogMae { log: l.path.display().to_string(), mae_rad: mae(l, params, options) }).collect()
}

fn mean(list: &[LogMae]) -> f64 {
    list.iter().map(|l| l.mae_rad).sum::<f64>() / list.len().max(1) as f64
}

/// The progress bar of a fit, counting `length` generations (hidden when `quiet`).
pub(super) fn generations_bar(length: u64, quiet: bool) -> ProgressBar {
    let bar = ProgressBar::new(length);
    if quiet {
        bar.set_draw_target(ProgressDrawTarget::hidden());
    } else {
        bar.set_style(ProgressStyle::with_template("{spinner} [{elapsed_precise}] {bar:30} {pos}/{len} generations  {msg}").unwrap_or_else(|_| ProgressStyle::default_bar()));
        bar.enable_steady_tick(std::time::Duration::from_millis(200));
    }
    bar
}

/// Whether the training logs ran the servo above the highest supply its vendor allows (the first
/// such log said in a notice): such a servo does not put the whole supply across its motor, and
/// the fit then includes that cap. On BAM's XL330 logs (7.4 V against the XL330's 6.0 V) the cap,
/// fitted at 5.2 V, takes the error on the 8 logs not fitted to from 59–63 to 38–39 mrad; on the
/// 12 V STS3215 logs (no limit known for the family) it is not fitted.
fn above_max_supply(family: &firmware::Family, logs: &[BenchLog], supply: Supply) -> bool {
    let Some(max) = family.max_supply else { return false };
    let volts = |log: &BenchLog| if supply.measured_for(log) { log.measured_supply.unwrap_or(log.vin) } else { log.vin };
    let Some(log) = logs.iter().find(|l| volts(l) > max) else { return false };
    eprintln!(
        "armscope: notice: {}: the servo ran at {:.1} V, above the {max:.1} V its vendor allows the {}: the motor's voltage cap is fitted too (--no-motor-voltage-limit: not)",
        log.path.display(),
        volts(log),
        family.name
    );
    true
}

/// `armscope identify`.
pub fn identify(args: &IdentifyArgs) -> Result<i32, Error> {
    if let Some(dataset) = &args.arm.from {
        if let Some(log) = args.logs.first() {
            return Err(Error::flag("--from", format!("identifies an arm from its episodes, not a servo from bench logs ({} given)", log.display())));
        }
        if args.actuator.is_some() {
            return Err(Error::flag("--from", "identifies an arm from its episodes: --actuator is for a servo's bench logs"));
        }
        return super::identify_arm::identify_arm(args, dataset);
    }
    let actuator = args.actuator.as_deref().unwrap_or_default();
    let family = firmware::family(actuator).ok_or_else(|| Error::flag("--actuator", format!("'{actuator}' is not a servo armscope knows ({})", firmware::family_names())))?;
    let generations = args.generations.unwrap_or(FitOptions::default().generations);
    if args.substeps == 0 {
        return Err(Error::flag("--substeps", "must be at least 1"));
    }
    if args.population == 1 {
        return Err(Error::flag("--population", "must be at least 2 (or 0 for CMA-ES's default)"));
    }
    if generations == 0 {
        return Err(Error::flag("--generations", "must be at least 1"));
    }
    if !(args.dt.is_finite() && args.dt > 0.0) {
        return Err(Error::flag("--dt", format!("must be a positive number of seconds (got {})", args.dt)));
    }
    let replay = ReplayOptions { step: args.step, substeps: args.substeps, supply: args.supply, reset_rows: None, ..Default::default() };
    let all: Vec<PathBuf> = args.logs.iter().chain(&args.validate).cloned().collect();
    let mut train = read_logs_for(&all, args.dt, args.supply)?;
    let validate = train.split_off(args.logs.len());
    for log in train.iter().chain(&validate) {
        if firmware::family(&log.actuator).map(|f| f.name) != Some(family.name) {
            return Err(Error::flag("LOG", format!("{}: field 'motor' is '{}', but --actuator is {}", log.path.display(), log.actuator, family.name)));
        }
    }
    let start = match &args.start {
        Some(path) => {
            let mut p = read_params(path, "--start")?;
            if p.family.name != family.name {
                return Err(Error::flag("--start", format!("{}: a {} file, but --actuator is {}", path.display(), p.family.name, family.name)));
            }
            if !args.friction_model.contains(p.friction.model) {
                return Err(Error::flag("--start", format!("{}: its {} friction is not part of {}: start from a file of a model {} contains", path.display(), p.friction.model.name(), args.friction_model.name(), args.friction_model.name())));
            }
            p.friction = p.friction.as_model(args.friction_model);
            Some(p)
        }
        None => None,
    };
    let fit_voltage_cap = args.fit_motor_voltage_limit || (!args.no_motor_voltage_limit && above_max_supply(&family, &train, args.supply));
    let space = Space::new(family, args.friction_model, args.fit_supply_resistance, fit_voltage_cap, !args.no_command_delay);
    let options = FitOptions { searches: args.searches, population: args.population, generations, refine_generations: args.refine_generations, polish_iterations: args.polish_iterations, seed: args.seed, start };
    let started = std::time::Instant::now();
    let bar = generations_bar(0, args.quiet);
    let progress = |p: Progress| {
        bar.set_length(p.generations as u64);
        bar.set_position(p.generation as u64);
        let search = if p.searches > 1 { format!(" search {}/{}", p.search + 1, p.searches) } else { String::new() };
        bar.set_message(format!("{}{search}: best {:.2} mrad", p.stage, 1e3 * p.best));
    };
    let found = fit(&space, &train, replay, &options, &progress).map_err(|m| Error::flag("identify", m))?;
    bar.finish_and_clear();
    let seconds = started.elapsed().as_secs_f64();
    let train_maes = maes(&train, &found.params, &replay);
    let validate_maes = maes(&validate, &found.params, &replay);
    let mut json = found.params.to_json();
    let file_json = json.clone();
    crate::runner::create_parent(&args.out)?;
    std::fs::write(&args.out, serde_json::to_string_pretty(&file_json).unwrap_or_default() + "\n").map_err(|e| Error::output(&args.out, e))?;
    if !args.quiet {
        println!(
            "{} {} fitted to {} log(s) in {seconds:.1} s ({} candidates: {} log replays run through, {} stopped once they could not do better; the windowed searches ended at {} mrad):",
            family.name,
            args.friction_model.name(),
            train.len(),
            found.evaluations,
            found.replays,
            found.replays_stopped,
            found.search_losses.iter().map(|l| format!("{:.2}", 1e3 * l)).collect::<Vec<_>>().join(", ")
        );
        let width = train.iter().chain(&validate).map(|l| l.name().chars().count()).max().unwrap_or(4);
        for (log, m) in train.iter().zip(&train_maes) {
            println!("  train     {:<width$} MAE {:>7.2} mrad", log.name(), 1e3 * m.mae_rad);
        }
        for (log, m) in validate.iter().zip(&validate_maes) {
            println!("  held out  {:<width$} MAE {:>7.2} mrad", log.name(), 1e3 * m.mae_rad);
        }
        println!("  mean MAE: trained on {:.2} mrad{}", 1e3 * mean(&train_maes), if validate.is_empty() { String::new() } else { format!(", held out {:.2} mrad", 1e3 * mean(&validate_maes)) });
        let p = &found.params;
        // the supply the first log was replayed on: its header's, or what its servo measured
        let volts = if replay.supply.measured_for(&train[0]) { train[0].measured_supply.unwrap_or(train[0].vin) } else { train[0].vin };
        println!(
            "  k_t {:.4} N·m/A, R {:.3} Ω (stall at {volts:.1} V: {:.3} N·m), armature {:.3e} kg·m², q_offset {:.4} rad{}",
            p.kt,
            p.resistance,
            p.kt * volts * family.max_duty / (p.resistance + p.supply_resistance),
            p.armature,
            p.q_offset,
            if args.fit_supply_resistance { format!(", supply resistance {:.3} Ω", p.supply_resistance) } else { String::new() }
        );
        if p.command_delay > 0.0 {
            println!("  command delay {:.1} ms", 1e3 * p.command_delay);
        }
        if fit_voltage_cap {
            println!("  motor voltage limit {:.3} V", p.motor_voltage_limit);
        }
        println!("wrote {}", args.out.display());
    }
    if let Some(path) = &args.summary_json {
        json = file_json;
        let summary = IdentifySummary {
            actuator: family.name.into(),
            model: args.friction_model.name().into(),
            step: args.step,
            supply: args.supply,
            evaluations: found.evaluations,
            replays: found.replays,
            replays_stopped: found.replays_stopped,
            seconds,
            train_mean_mae_rad: mean(&train_maes),
            validate_mean_mae_rad: (!validate_maes.is_empty()).then(|| mean(&validate_maes)),
            train: train_maes,
            validate: validate_maes,
            params: json,
        };
        crate::runner::create_parent(path)?;
        std::fs::write(path, serde_json::to_string_pretty(&summary).unwrap_or_default() + "\n").map_err(|e| Error::output(path, e))?;
    }
    Ok(0)
}
