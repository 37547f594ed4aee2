//! `--backend` and `--adapter`: which GPU a command draws on, and the
//! renderer's measuring switches, which the binary (never the library) reads
//! from the environment.

use strata_render::options::{BeamSearch, DepthMode, ExactOptions, RenderOptions, TexelWalk};
use strata_render::{AdapterChoice, BackendChoice, Gpu};

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
            name: std::env::var("WGPU_ADAPTER_NAME").ok(),
        }
    }

    /// The chosen adapter's device, with [`render_options`].
    pub fn open(&self) -> anyhow::Result<Gpu> {
        let mut gpu = Gpu::open(&self.choice())?;
        gpu.options = render_options();
        Ok(gpu)
    }
}

pub fn parse_backend(s: &str) -> anyhow::Result<BackendChoice> {
    s.parse()
}

/// The renderer's measuring switches and test hook from the environment
/// (`bench/ray-exact.md` has what each measured): `STRATA_SHADOW_REUSE=1`
/// keeps the shadow map while its frame and the terrain are unchanged;
/// `STRATA_SHADOW_CULL=0` casts the whole map; `STRATA_DEPTH_ATTACHMENT=1`
/// copies depth into the shared target every frame;
/// `STRATA_EXACT_SHADOW=shared|exact`, `STRATA_EXACT_DEPTH=blit|points|load`,
/// `STRATA_EXACT_CLIMB=all`, `STRATA_EXACT_RATIO=2|4`,
/// `STRATA_EXACT_BEAM=off|serial|wide|wide-pass` (no beam, the serial
/// pre-pass, the wide search in the march or in a pre-pass; default
/// wide), `STRATA_EXACT_SHADOW_ROUNDS=1..8` (the shadow blocks' wide
/// search's most rounds), `STRATA_EXACT_FUSED_DESCENT=on|off` (a descent
/// into the texels tests the texel in its iteration, or is an iteration of
/// its own as by default), `STRATA_EXACT_CAVE_SKIP=off` (no
/// tile skipped between its floors and slabs), `STRATA_EXACT_BEAM_TEXELS=off`
/// (the beams' finest test on 4-texel tiles),
/// `STRATA_EXACT_TEXEL_BLOCKS=plane|beside` (a 4x4 tile's texels walked
/// from the texel plane, its words loaded on the way down or beside the
/// tile's maximum), `STRATA_EXACT_KEEP=off` (cast every shadow block a
/// frame reads and shade in a pass of its own, keeping nothing from earlier
/// frames), `STRATA_EXACT_COVER=off|N` (never cast the view's cover ahead
/// of the march, or up to N blocks a frame), `STRATA_EXACT_SHADE_CHAIN=on|off`
/// (the shading's fetches one after another), `STRATA_EXACT_EDIT_KEEP=off`
/// (an edit forgets every kept shadow block) configure `ray-exact`;
/// `STRATA_EXACT_STATS=1` prints its statistics;
/// `STRATA_TEST_OVERSIZE_BUILD=METHOD` makes that method's build ask for a
/// buffer over the device's limit (the README's way to see a refused build).
pub fn render_options() -> RenderOptions {
    render_options_from(|name| std::env::var(name).ok())
}

fn render_options_from(var: impl Fn(&str) -> Option<String>) -> RenderOptions {
    let is = |name: &str, value: &str| var(name).is_some_and(|v| v == value);
    let e = ExactOptions::DEFAULT;
    RenderOptions {
        shadow_reuse: is("STRATA_SHADOW_REUSE", "1"),
        shadow_cull: !is("STRATA_SHADOW_CULL", "0"),
        depth_attachment: is("STRATA_DEPTH_ATTACHMENT", "1"),
        exact: ExactOptions {
            depth: match var("STRATA_EXACT_DEPTH").as_deref() {
                Some("points") => DepthMode::Points,
                Some("load") => DepthMode::BlitLoad,
                Some("blit") => DepthMode::Blit,
                _ => e.depth,
            },
            exact_shadow: match var("STRATA_EXACT_SHADOW").as_deref() {
                Some("shared") => false,
                Some("exact") => true,
                _ => e.exact_shadow,
            },
            climb: if is("STRATA_EXACT_CLIMB", "all") {
                8
            } else {
                e.climb
            },
            log_ratio: match var("STRATA_EXACT_RATIO").as_deref() {
                Some("4") => 2,
                Some("2") => 1,
                _ => e.log_ratio,
            },
            beam: !is("STRATA_EXACT_BEAM", "off"),
            beam_search: match var("STRATA_EXACT_BEAM").as_deref() {
                Some("serial") => BeamSearch::Serial,
                Some("wide") => BeamSearch::Wide,
                Some("wide-pass") => BeamSearch::WidePass,
                _ => e.beam_search,
            },
            shadow_rounds: var("STRATA_EXACT_SHADOW_ROUNDS")
                .and_then(|v| v.parse().ok())
                .filter(|n| (1..=8).contains(n))
                .unwrap_or(e.shadow_rounds),
            fused_descent: match var("STRATA_EXACT_FUSED_DESCENT").as_deref() {
                Some("on") => true,
                Some("off") => false,
                _ => e.fused_descent,
            },
            cave_skip: !is("STRATA_EXACT_CAVE_SKIP", "off"),
            beam_texels: !is("STRATA_EXACT_BEAM_TEXELS", "off"),
            shadow_keep: !is("STRATA_EXACT_KEEP", "off"),
            shade_fetch_chain: match var("STRATA_EXACT_SHADE_CHAIN").as_deref() {
                Some("on") => true,
                Some("off") => false,
                _ => e.shade_fetch_chain,
            },
            edit_keep: !is("STRATA_EXACT_EDIT_KEEP", "off"),
            cover_budget: match var("STRATA_EXACT_COVER").as_deref() {
                Some("off") => 0,
                Some(n) => n.parse().unwrap_or(e.cover_budget),
                None => e.cover_budget,
            },
            texel_walk: match var("STRATA_EXACT_TEXEL_BLOCKS").as_deref() {
                Some("off") => TexelWalk::Terrain,
                Some("plane") => TexelWalk::Plane,
                Some("beside") => TexelWalk::PlaneBeside,
                _ => e.texel_walk,
            },
            ..e
        },
        exact_stats: is("STRATA_EXACT_STATS", "1"),
        oversize_build: var("STRATA_TEST_OVERSIZE_BUILD").filter(|m| !m.is_empty()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn no_variables_give_the_product_and_each_switch_reads_its_own() {
        assert_eq!(render_options_from(|_| None), RenderOptions::default());
        let o = render_options_from(|n| match n {
            "STRATA_SHADOW_CULL" => Some("0".into()),
            "STRATA_EXACT_DEPTH" => Some("points".into()),
            "STRATA_EXACT_RATIO" => Some("2".into()),
            "STRATA_EXACT_BEAM" => Some("off".into()),
            "STRATA_EXACT_SHADOW_ROUNDS" => Some("1".into()),
            "STRATA_EXACT_FUSED_DESCENT" => Some("on".into()),
            "STRATA_EXACT_CAVE_SKIP" => Some("off".into()),
            "STRATA_EXACT_BEAM_TEXELS" => Some("off".into()),
            "STRATA_EXACT_KEEP" => Some("off".into()),
            "STRATA_EXACT_COVER" => Some("off".into()),
            "STRATA_EXACT_EDIT_KEEP" => Some("off".into()),
            "STRATA_EXACT_TEXEL_BLOCKS" => Some("beside".into()),
            "STRATA_TEST_OVERSIZE_BUILD" => Some("voxel".into()),
            _ => None,
        });
        assert!(!o.shadow_cull && !o.shadow_reuse && !o.exact.beam);
        assert_eq!(o.exact.shadow_rounds, 1);
        assert!(o.exact.fused_descent && o.exact.texel_walk == TexelWalk::PlaneBeside);
        assert_eq!(
            render_options_from(|_| None).exact.texel_walk,
            TexelWalk::Terrain
        );
        assert!(!o.exact.cave_skip && !o.exact.beam_texels && !o.exact.shadow_keep);
        assert!(render_options_from(|_| None).exact.shadow_keep);
        assert_eq!(o.exact.cover_budget, 0);
        assert!(!o.exact.edit_keep && render_options_from(|_| None).exact.edit_keep);
        let n = render_options_from(|n| (n == "STRATA_EXACT_COVER").then(|| "4096".into()));
        assert_eq!(n.exact.cover_budget, 4096);
        assert_eq!(render_options_from(|_| None).exact.cover_budget, 256);
        assert!(render_options_from(|_| None).exact.beam_texels);
        assert!(render_options_from(|_| None).exact.cave_skip);
        assert!(render_options_from(|_| None).exact.beam);
        assert!(!render_options_from(|_| None).exact.fused_descent);
        for (value, search) in [
            ("serial", BeamSearch::Serial),
            ("wide", BeamSearch::Wide),
            ("wide-pass", BeamSearch::WidePass),
        ] {
            let o = render_options_from(|n| (n == "STRATA_EXACT_BEAM").then(|| value.into()));
            assert!(o.exact.beam && o.exact.beam_search == search, "{value}");
        }
        assert_eq!((o.exact.depth, o.exact.log_ratio), (DepthMode::Points, 1));
        assert_eq!(o.oversize_build.as_deref(), Some("voxel"));
    }
}
