//! `lucent inspect`: a mesh, texture, MTL or scene file loaded and summarised (or what is wrong
//! with it).

use lucent::{frame, Result};

use crate::cli::InspectArgs;

/// Prints the summary of `args.file`.
pub fn run(args: InspectArgs) -> Result<()> {
    print!("{}", frame::inspect::inspect_file(&args.file)?);
    Ok(())
}
