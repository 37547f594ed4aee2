//! `scattered:D` or `scattered:X,Y,Z`: the footprint grid's density.

use super::super::knobs::{
    Flag, Knobs, Slider, SliderKind, Sweep, number_triple, plain, show_triple,
};

pub static KNOBS: Knobs = Knobs {
    grammar: "D or X,Y,Z",
    default: Some("4"),
    parse: |text, s| {
        s.scatter_density = plain(number_triple(text, "density"))?;
        Ok(())
    },
    describe: |s| format!("density={}", show_triple(&s.scatter_density)),
    keep: |from, to| to.scatter_density = from.scatter_density,
    sliders: &[Slider {
        name: "density",
        label: "density",
        kind: SliderKind::Number { min: 0.5, max: 8.0 },
        get: |s| s.scatter_density[0],
        put: |s, v| s.scatter_density = [v; 3],
        live: true,
    }],
    flags: &[Flag {
        long: "scatter-density",
        value: Some("X,Y,Z"),
        help: "`scattered`: grid density X,Y,Z in screen terms (4 → 1.25 samples per pixel across, 1 per pixel along, 1.25 per pixel of projected height), or one D for all three.",
        default: |s| show_triple(&s.scatter_density),
        apply: |text, s| {
            s.scatter_density = number_triple(text, "density")?;
            Ok(())
        },
    }],
};

/// `strata tune`'s sweep of the density.
pub static SWEEP: Sweep = Sweep {
    order: 3,
    knob: "density",
    full: &["1", "2", "4", "8"],
    quick: &["1", "4", "8"],
    at_paper_size: false,
};
