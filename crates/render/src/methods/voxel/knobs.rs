//! `voxel:X,Y,Z/STEPS` (`voxel-compute` too): the occupancy voxel size and
//! the traversal's step budget.

use super::super::contract::MethodSettings;
use super::super::knobs::{Flag, Knobs, Slider, Sweep, count, count_triple, plain, show_triple};
use super::super::march_beam::{NO_BEAM_FLAG, nobeam_tag, split_nobeam};
use anyhow::bail;

pub static KNOBS: Knobs = Knobs {
    grammar: "X,Y,Z/STEPS, (X,Y,Z)/STEPS, X,Y,Z or /STEPS, each optionally followed by /nobeam",
    default: Some("4,8,2/100"),
    parse,
    describe: |s| {
        let [x, y, z] = s.voxel_size;
        format!(
            "grid=({x},{y},{z}) steps={}{}",
            s.voxel_steps,
            nobeam_tag(s)
        )
    },
    keep: |from, to| {
        to.voxel_size = from.voxel_size;
        to.voxel_steps = from.voxel_steps;
        to.march_beam = from.march_beam;
    },
    sliders: &[Slider::count(
        "voxel-steps",
        "voxel steps",
        (8, 400),
        |s| s.voxel_steps as f32,
        |s, v| s.voxel_steps = v as u32,
    )],
    flags: &[
        Flag {
            long: "voxel-size",
            value: Some("X,Y,Z"),
            help: "`voxel`, `voxel-compute`: occupancy voxel size in texels, X,Y,Z.",
            default: |s| show_triple(&s.voxel_size),
            apply: |text, s| {
                s.voxel_size = count_triple(text, "voxel size")?;
                Ok(())
            },
        },
        Flag {
            long: "voxel-steps",
            value: Some("N"),
            help: "`voxel`, `voxel-compute`: traversal step budget.",
            default: |s| s.voxel_steps.to_string(),
            apply: |text, s| {
                s.voxel_steps = count(text)?;
                Ok(())
            },
        },
        NO_BEAM_FLAG,
    ],
};

/// `X,Y,Z/STEPS`, `(X,Y,Z)/STEPS`, `X,Y,Z` or `/STEPS`, then `/nobeam` or not.
fn parse(text: &str, s: &mut MethodSettings) -> anyhow::Result<()> {
    let (text, beam) = split_nobeam(text);
    s.march_beam = beam;
    let (grid, steps) = match text.split_once('/') {
        Some((g, st)) => (g, Some(st)),
        None => (text, None),
    };
    let grid = grid.trim().trim_start_matches('(').trim_end_matches(')');
    if !grid.is_empty() {
        let v: Vec<u32> = grid
            .split(',')
            .map(|t| plain(count(t)))
            .collect::<anyhow::Result<_>>()?;
        let [x, y, z] = v[..] else {
            bail!("the voxel grid needs three sizes X,Y,Z")
        };
        s.voxel_size = [x, y, z];
    }
    if let Some(st) = steps {
        s.voxel_steps = plain(count(st))?;
    }
    Ok(())
}

/// `strata tune`'s sweep: two grids, each at five step budgets.
pub static SWEEP: Sweep = Sweep {
    order: 1,
    knob: "grid / steps",
    full: &[
        "4,8,2/40",
        "4,8,2/70",
        "4,8,2/100",
        "4,8,2/200",
        "4,8,2/400",
        "2,4,1/40",
        "2,4,1/70",
        "2,4,1/100",
        "2,4,1/200",
        "2,4,1/400",
    ],
    quick: &[
        "4,8,2/40",
        "4,8,2/100",
        "4,8,2/400",
        "2,4,1/40",
        "2,4,1/100",
        "2,4,1/400",
    ],
    at_paper_size: false,
};
