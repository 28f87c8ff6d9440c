//! `armscope.size(**flags)` and `armscope.batch(manifest, **flags)`: the commands in this process —
//! their flags parsed by the same command line, their tables printed as the command prints them —
//! and their results back as the JSON the command writes (size.json, summary.json), parsed.

use clap::Parser;
use pyo3::prelude::*;
use std::path::PathBuf;

#[derive(Parser)]
#[command(name = "armscope.size", no_binary_name = true, disable_help_flag = true)]
struct SizeCall {
    #[command(flatten)]
    args: armscope::cli::SizeArgs,
}

#[derive(Parser)]
#[command(name = "armscope.batch", no_binary_name = true, disable_help_flag = true)]
struct BatchCall {
    #[command(flatten)]
    args: armscope::cli::BatchArgs,
}

/// A scratch folder for the command's files, removed after its JSON is read.
fn scratch() -> PyResult<tempfile::TempDir> {
    tempfile::Builder::new().prefix("armscope-").tempdir().map_err(crate::error)
}

/// `armscope size ARGV`: the text of the size.json it writes (to `--out`, else to a scratch folder).
#[pyfunction]
pub fn size(py: Python<'_>, argv: Vec<String>) -> PyResult<String> {
    // `--out` has a default: whether the caller gave one is in the arguments
    let given = argv.iter().any(|a| a == "--out" || a.starts_with("--out="));
    let mut call = SizeCall::try_parse_from(&argv).map_err(|e| crate::error(format!("size: {}", armscope::cli::parse_error_line(&e))))?;
    let folder = if given { None } else { Some(scratch()?) };
    if let Some(f) = &folder {
        call.args.out = f.path().to_path_buf();
    }
    py.detach(|| armscope::cli::size(&call.args)).map_err(crate::error)?;
    std::fs::read_to_string(call.args.out.join("size.json")).map_err(crate::error)
}

/// `armscope batch ARGV`: the text of the summary (or shard summary) JSON it writes, failed
/// experiments in it with their errors (to `--out`, else to a scratch folder).
#[pyfunction]
pub fn batch(py: Python<'_>, argv: Vec<String>) -> PyResult<String> {
    let mut call = BatchCall::try_parse_from(&argv).map_err(|e| crate::error(format!("batch: {}", armscope::cli::parse_error_line(&e))))?;
    if call.args.action.is_some() {
        return Err(crate::error("batch: merge is the command's (`armscope batch merge DIR…`)"));
    }
    let folder = if call.args.out.is_none() { Some(scratch()?) } else { None };
    let out: PathBuf = match &folder {
        Some(f) => f.path().to_path_buf(),
        None => call.args.out.clone().unwrap_or_default(),
    };
    call.args.out = Some(out.clone());
    py.detach(|| armscope::cli::batch(&call.args)).map_err(crate::error)?;
    let shard = call.args.shard.as_deref().map(armscope::batch::parse_shard).transpose().map_err(crate::error)?;
    let file = out.join(format!("{}.json", armscope::batch::table_stem(shard.map(|(i, n)| [i, n]))));
    std::fs::read_to_string(&file).map_err(crate::error)
}
