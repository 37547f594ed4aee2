//! `--level DIR`: the world a command works on; the built-in generated world
//! when absent, so a newcomer needs no setup.

use std::path::PathBuf;

#[derive(clap::Args, Clone, Debug)]
pub struct WorldArgs {
    /// World directory (`world.ini` + map + palette). Default: the built-in generated world.
    #[arg(long, value_name = "DIR")]
    pub level: Option<PathBuf>,
    /// Derive the cave ceiling with vange-rs's `+0` convention instead of the original game's `+1`.
    #[arg(long)]
    pub vange_rs_mid: bool,
}
