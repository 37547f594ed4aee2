//! `--backend` and `--adapter`: which GPU a command draws on.

use strata_render::{AdapterChoice, BackendChoice};

#[derive(clap::Args, Clone, Debug, Default)]
pub struct AdapterArgs {
    /// wgpu backend: vulkan, gl, dx12, metal or auto (auto honours WGPU_BACKEND).
    #[arg(long, value_name = "NAME", default_value = "auto", value_parser = parse_backend)]
    pub backend: BackendChoice,
    /// Adapter index as `strata adapters` lists it for the same --backend
    /// [default: the high-performance adapter, or WGPU_ADAPTER_NAME's].
    #[arg(long, value_name = "N")]
    pub adapter: Option<usize>,
}

impl AdapterArgs {
    pub fn choice(&self) -> AdapterChoice {
        AdapterChoice {
            backend: self.backend,
            index: self.adapter,
        }
    }
}

pub fn parse_backend(s: &str) -> anyhow::Result<BackendChoice> {
    s.parse()
}
