//! `armscope compare`: one comparison recording from finished runs.

use super::*;

#[derive(Args, Debug)]
pub struct CompareArgs {
    /// The runs' .mcap files (each run is labelled with its file name; runs whose names
    /// collide are labelled `FOLDER/NAME`).
    #[arg(required = true, value_name = "RUN.mcap")]
    pub inputs: Vec<PathBuf>,
    /// The comparison recording to write.
    #[arg(long, value_name = "PATH", default_value = "recordings/comparison.rrd")]
    pub out: PathBuf,
}


/// `armscope compare`.
pub fn compare(args: &CompareArgs) -> Result<i32, Error> {
    let runs: Vec<crate::batch::ComparedRun> = run_labels(&args.inputs)
        .into_iter()
        .zip(&args.inputs)
        .map(|(label, p)| crate::batch::ComparedRun { label, mcap: p.clone() })
        .collect();
    crate::runner::create_parent(&args.out)?;
    crate::batch::build_comparison(&runs, &args.out, "comparison")?;
    println!("Comparison of {} runs: {}   open in Rerun: rerun {}", runs.len(), args.out.display(), args.out.display());
    Ok(0)
}

/// Each run's label: its file stem, or `FOLDER_STEM` when two runs share a stem (two batches'
/// `fox.mcap`), or the stem and its position when even that collides — two runs under one
/// label would overlay into one series.
pub fn run_labels(inputs: &[PathBuf]) -> Vec<String> {
    let stem = |p: &PathBuf| p.file_stem().map_or("run".into(), |s| s.to_string_lossy().to_string());
    let stems: Vec<String> = inputs.iter().map(stem).collect();
    let count = |labels: &[String], l: &String| labels.iter().filter(|o| *o == l).count();
    let with_folder: Vec<String> = inputs
        .iter()
        .zip(&stems)
        .map(|(p, s)| {
            if count(&stems, s) == 1 {
                return s.clone();
            }
            let folder = p.parent().and_then(|d| d.file_name()).map(|d| d.to_string_lossy().to_string());
            folder.map_or(s.clone(), |f| format!("{f}_{s}"))
        })
        .collect();
    with_folder
        .iter()
        .enumerate()
        .map(|(i, l)| if count(&with_folder, l) == 1 { l.clone() } else { format!("{l}_{}", i + 1) })
        .collect()
}
