//! `armscope batch`: a manifest of experiments, in parallel or in shards, and `batch merge`.

use super::*;

#[derive(Args, Debug)]
#[command(args_conflicts_with_subcommands = true)]
pub struct BatchArgs {
    #[command(subcommand)]
    pub action: Option<BatchAction>,
    /// The manifest.
    #[arg(value_name = "MANIFEST", default_value = crate::builtin::DEFAULT_MANIFEST)]
    pub manifest: PathBuf,
    /// Experiments run at once (default: the number of cores).
    #[arg(long)]
    pub jobs: Option<usize>,
    /// Run only shard I of N (I from 0), e.g. a Slurm array task (--array=0-3):
    /// --shard $SLURM_ARRAY_TASK_ID/$SLURM_ARRAY_TASK_COUNT.
    #[arg(long, value_name = "I/N")]
    pub shard: Option<String>,
    /// Output folder (default: recordings/BATCH, BATCH the manifest's name).
    #[arg(long, value_name = "DIR")]
    pub out: Option<PathBuf>,
    /// Skip the comparison recording.
    #[arg(long)]
    pub no_compare: bool,
    /// Compress every experiment's recordings (as `run --compress`): smaller files, more CPU.
    #[arg(long)]
    pub compress: bool,
    /// Every experiment's MCAP encoding (as `run --mcap-encoding`; an experiment's own
    /// `mcap_encoding` wins).
    #[arg(long, value_enum, default_value_t = crate::recorder::McapEncoding::Foxglove)]
    pub mcap_encoding: crate::recorder::McapEncoding,
}

#[derive(Subcommand, Debug)]
pub enum BatchAction {
    /// Join the shard summaries in DIR… into one set of tables (and the comparison recording).
    Merge {
        #[arg(required = true)]
        dirs: Vec<PathBuf>,
        /// Where to write the merged tables (default: the first DIR).
        #[arg(long, value_name = "DIR")]
        out: Option<PathBuf>,
    },
}


/// `armscope batch`.
pub fn batch(args: &BatchArgs) -> Result<i32, Error> {
    use crate::batch::{BatchOptions, merge_summaries, parse_shard, write_tables};
    let summary = match &args.action {
        Some(BatchAction::Merge { dirs, out }) => {
            let merged = merge_summaries(dirs)?;
            let dir = out.clone().unwrap_or_else(|| dirs[0].clone());
            std::fs::create_dir_all(&dir).map_err(|e| Error::output(&dir, e))?;
            let mut files = write_tables(&dir, &merged)?;
            files.extend(crate::batch::write_comparison(&merged, dirs, &dir)?);
            report_batch(&merged, &files);
            merged
        }
        None => {
            let options = BatchOptions {
                manifest: args.manifest.clone(),
                jobs: args.jobs.unwrap_or_else(|| std::thread::available_parallelism().map_or(1, |n| n.get())),
                shard: args.shard.as_deref().map(parse_shard).transpose()?,
                out: args.out.clone(),
                compare: !args.no_compare,
                compress: args.compress,
                mcap_encoding: args.mcap_encoding,
                progress: true,
            };
            if options.jobs == 0 {
                return Err(Error::flag("--jobs", "must be at least 1"));
            }
            install_interrupt_handler();
            INTERRUPTED.store(false, Ordering::SeqCst);
            let (summary, files) = crate::batch::run_batch(&options, Some(&INTERRUPTED))?;
            if let (Some((i, n)), true) = (options.shard, summary.experiments.is_empty()) {
                let all = crate::batch::load_manifest(&options.manifest)?.experiments.len();
                eprintln!("armscope: notice: shard {i} of {n} holds none of the manifest's {all} experiments (more shards than experiments): its empty summary is written for the merge");
            }
            report_batch(&summary, &files);
            summary
        }
    };
    let failed = summary.experiments.iter().filter(|e| e.status != "completed").count();
    Ok(if failed == 0 { 0 } else { 1 })
}

fn report_batch(summary: &crate::batch::BatchSummary, files: &[PathBuf]) {
    print!("{}", crate::batch::BatchSummary::markdown(summary));
    for e in summary.experiments.iter().filter(|e| e.status != "completed") {
        eprintln!("armscope: experiment '{}' {}: {}", e.name, e.status, e.error.clone().unwrap_or_default());
    }
    println!("\nWritten: {}", files.iter().map(|f| f.display().to_string()).collect::<Vec<_>>().join(", "));
}
