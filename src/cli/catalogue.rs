//! `armscope catalogue`: the motors and reductions `size` and motor files choose from; `--check FILE`
//! validates a catalogue of your own.

use super::*;
use crate::actuator::Catalogue;

#[derive(Args, Debug)]
pub struct CatalogueArgs {
    /// Check this catalogue file (one line naming the entry and field if it is malformed) and list
    /// the built-in catalogue with it on top.
    #[arg(long, value_name = "FILE")]
    pub check: Option<PathBuf>,
    /// The listing as JSON on stdout.
    #[arg(long)]
    pub json: bool,
}

/// `armscope catalogue`.
pub fn catalogue(args: &CatalogueArgs) -> Result<i32, Error> {
    let catalogue = match &args.check {
        Some(path) => {
            let own = Catalogue::load(path)?;
            let unsourced: Vec<&String> = own.entries.keys().chain(own.reductions.keys()).filter(|n| own.source_of(n).is_none()).collect();
            eprintln!("armscope: {}: {} motors, {} reductions, valid", path.display(), own.entries.len(), own.reductions.len());
            if !unsourced.is_empty() {
                eprintln!("armscope: notice: {}: no 'source' on {}: listed as the user's own", path.display(), unsourced.iter().map(|s| s.as_str()).collect::<Vec<_>>().join(", "));
            }
            Catalogue::with_user_file(path)?
        }
        None => Catalogue::load(std::path::Path::new(crate::actuator::catalogue::DEFAULT_CATALOGUE))?,
    };
    let listing = catalogue.listing();
    if args.json {
        println!("{}", serde_json::to_string_pretty(&listing).map_err(|e| Error::flag("--json", e.to_string()))?);
    } else {
        print!("{}", listing.table());
    }
    Ok(0)
}
