//! `strata adapters`: every adapter wgpu finds, what it can do, and which
//! methods it runs (with the reason for each it cannot).

use crate::adapter_arg::parse_backend;
use strata_render::BackendChoice;
use strata_render::adapter::{AdapterListing, list_adapters};

#[derive(clap::Args)]
pub struct Args {
    /// Only this backend's adapters: vulkan, gl, dx12, metal or auto (every backend).
    #[arg(long, value_name = "NAME", default_value = "auto", value_parser = parse_backend)]
    pub backend: BackendChoice,
    /// Print JSON (one array of adapters) instead of text.
    #[arg(long)]
    pub json: bool,
}

pub fn run(args: Args) -> anyhow::Result<()> {
    let adapters = list_adapters(args.backend);
    if args.json {
        println!("{}", serde_json::to_string_pretty(&adapters)?);
        return Ok(());
    }
    if adapters.is_empty() {
        anyhow::bail!(
            "no adapter found on backend `{}` (install mesa-vulkan-drivers for lavapipe, \
             libegl1 + libgl1-mesa-dri for llvmpipe's GL)",
            args.backend
        );
    }
    for adapter in &adapters {
        print!("{}", describe(adapter, args.backend));
    }
    Ok(())
}

fn yes_no(b: bool) -> &'static str {
    if b { "yes" } else { "no" }
}

/// The text block of one adapter.
fn describe(a: &AdapterListing, backend: BackendChoice) -> String {
    let c = &a.capabilities;
    let flag = match backend {
        BackendChoice::Auto => format!("--adapter {}", a.index),
        b => format!("--backend {b} --adapter {}", a.index),
    };
    let mut out = format!(
        "[{}] {} ({}; {})\n    driver: {} {}\n",
        a.index, a.name, a.backend, a.device_type, a.driver, a.driver_info
    );
    out += &format!("    select with: {flag}\n");
    if let Some(why) = &a.refused {
        out += &format!("    REFUSED: {why}\n");
    }
    out += &format!(
        "    timestamps: {}   compute: {}   storage textures: {}   storage in vertex / fragment: {} / {}   depth copies: {}\n",
        yes_no(c.timestamps),
        yes_no(c.compute),
        yes_no(c.storage_textures),
        yes_no(c.vertex_storage),
        yes_no(c.fragment_storage),
        yes_no(c.depth_copies),
    );
    out += &format!(
        "    limits: texture side {}, layers {}, storage binding {} MiB, buffer {} MiB\n",
        c.max_texture_2d,
        c.max_texture_layers,
        c.max_storage_binding >> 20,
        c.max_buffer >> 20
    );
    let runs: Vec<&str> = a
        .methods
        .iter()
        .filter(|m| m.refused.is_none())
        .map(|m| m.name.as_str())
        .collect();
    out += &format!(
        "    methods: {}\n",
        if runs.is_empty() {
            "none".to_string()
        } else {
            runs.join(", ")
        }
    );
    for why in a.methods.iter().filter_map(|m| m.refused.as_ref()) {
        out += &format!("      refused: {why}\n");
    }
    out
}
