//! `armscope compare`: one comparison recording from finished runs.

use super::*;

#[derive(Args, Debug)]
pub struct CompareArgs {
    /// The runs' .mcap files (each run is labelled with its file name).
    #[arg(required = true, value_name = "RUN.mcap")]
    pub inputs: Vec<PathBuf>,
    /// The comparison recording to write.
    #[arg(long, value_name = "PATH", default_value = "recordings/comparison.rrd")]
    pub out: PathBuf,
}


/// `armscope compare`.
pub fn compare(args: &CompareArgs) -> Result<i32, Error> {
    let runs: Vec<crate::batch::ComparedRun> = args
        .inputs
        .iter()
        .map(|p| crate::batch::ComparedRun { label: p.file_stem().map_or("run".into(), |s| s.to_string_lossy().to_string()), mcap: p.clone() })
        .collect();
    crate::runner::create_parent(&args.out)?;
    crate::batch::build_comparison(&runs, &args.out, "comparison")?;
    println!("Comparison of {} runs: {}   open in Rerun: rerun {}", runs.len(), args.out.display(), args.out.display());
    Ok(0)
}
