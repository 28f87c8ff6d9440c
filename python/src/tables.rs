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

/// `--out` when the caller gave none: a scratch folder, removed after its JSON is read.
fn out_folder(given: bool, out: &mut PathBuf) -> PyResult<Option<tempfile::TempDir>> {
    if given {
        return Ok(None);
    }
    let scratch = tempfile::Builder::new().prefix("armscope-").tempdir().map_err(crate::error)?;
    *out = scratch.path().to_path_buf();
    Ok(Some(scratch))
}

/// `armscope size ARGV`: the text of the size.json it writes.
#[pyfunction]
pub fn size(py: Python<'_>, argv: Vec<String>) -> PyResult<String> {
    let given = argv.iter().any(|a| a == "--out" || a.starts_with("--out="));
    let mut call = SizeCall::try_parse_from(&argv).map_err(|e| crate::error(format!("size: {}", crate::run::parse_error(&e))))?;
    let _scratch = out_folder(given, &mut call.args.out)?;
    let out = call.args.out.clone();
    py.detach(|| armscope::cli::size(&call.args)).map_err(crate::error)?;
    std::fs::read_to_string(out.join("size.json")).map_err(crate::error)
}

/// `armscope batch ARGV`: the text of the summary.json it writes (failed experiments in it, with
/// their errors).
#[pyfunction]
pub fn batch(py: Python<'_>, argv: Vec<String>) -> PyResult<String> {
    let given = argv.iter().any(|a| a == "--out" || a.starts_with("--out="));
    let mut call = BatchCall::try_parse_from(&argv).map_err(|e| crate::error(format!("batch: {}", crate::run::parse_error(&e))))?;
    if call.args.action.is_some() {
        return Err(crate::error("batch: merge is the command's (`armscope batch merge DIR…`)"));
    }
    let scratch = out_folder(given, &mut PathBuf::new())?;
    if let Some(s) = &scratch {
        call.args.out = Some(s.path().to_path_buf());
    }
    let out = call.args.out.clone();
    py.detach(|| armscope::cli::batch(&call.args)).map_err(crate::error)?;
    let manifest_name = armscope::batch::load_manifest(&call.args.manifest).map_err(crate::error)?.name;
    let folder = out.unwrap_or_else(|| PathBuf::from("recordings").join(manifest_name));
    let file = match &call.args.shard {
        Some(spec) => {
            let (i, n) = armscope::batch::parse_shard(spec).map_err(crate::error)?;
            folder.join(format!("summary.shard-{i}-of-{n}.json"))
        }
        None => folder.join("summary.json"),
    };
    std::fs::read_to_string(&file).map_err(crate::error)
}
