//! `latvox topo`: density field to STL and CAD.
use clap::Args;
use latvox::Result;

pub(crate) const EXAMPLES: &str = "";

#[derive(Args)]
pub struct TopoArgs {}

pub fn run(_a: &TopoArgs, _quiet: bool) -> Result<i32> {
    Ok(2)
}
