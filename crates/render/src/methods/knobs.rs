//! A method's knobs as everything outside the renderer sees them: the
//! `name:SETTING` form the command line, the results and the page take, the
//! results' record of what it read, the viewer's sliders (and a script's
//! `set`), `strata render`'s flags and `strata tune`'s sweep. Each method
//! declares its own in its module; [`super::METHODS`] carries them, and the
//! CLI, the bench, the viewer and the page read them from there.

use super::contract::MethodSettings;
use anyhow::bail;

/// One method's knobs (shared by the variants of one method: `ray` and
/// `ray-compute` read the same field).
pub struct Knobs {
    /// The form of `name:SETTING`, for messages (`N`, `N or N/refine`);
    /// empty when the method has no setting.
    pub grammar: &'static str,
    /// The built-in (the paper's) setting in that form; `None`: no setting.
    pub default: Option<&'static str>,
    /// Read `SETTING` into the fields this method reads.
    pub parse: fn(&str, &mut MethodSettings) -> anyhow::Result<()>,
    /// What the method read, for the results' settings record, after its
    /// name (`steps=128`); empty when it reads nothing.
    pub describe: fn(&MethodSettings) -> String,
    /// Copy the fields this method reads from the first settings into the
    /// second (two settings are the same for a method when these are).
    pub keep: fn(&MethodSettings, &mut MethodSettings),
    /// The viewer's sliders (and a script's `set NAME VALUE`).
    pub sliders: &'static [Slider],
    /// `strata render`'s flags.
    pub flags: &'static [Flag],
}

impl Knobs {
    /// A method without settings.
    pub const NONE: Knobs = Knobs {
        grammar: "",
        default: None,
        parse: no_setting,
        describe: |_| String::new(),
        keep: |_, _| {},
        sliders: &[],
        flags: &[],
    };
}

fn no_setting(_: &str, _: &mut MethodSettings) -> anyhow::Result<()> {
    bail!("the method has no setting to change")
}

/// One slider of the viewer's panel; a script's `set NAME VALUE` moves it.
pub struct Slider {
    /// The name `set` takes (`ray-steps`).
    pub name: &'static str,
    /// The panel's text (`ray steps`).
    pub label: &'static str,
    /// What values it takes.
    pub kind: SliderKind,
    /// Its value in `settings`.
    pub get: fn(&MethodSettings) -> f32,
    /// Write a value (already checked against `kind`).
    pub put: fn(&mut MethodSettings, f32),
    /// The method takes it in place while dragging; otherwise (a rebuild)
    /// when the drag ends.
    pub live: bool,
}

/// The values a [`Slider`] takes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum SliderKind {
    /// A whole number; the panel offers `min..=max`, a script any positive one.
    Count {
        /// The panel's least value.
        min: u32,
        /// The panel's largest value.
        max: u32,
    },
    /// A number; the panel offers `min..=max` (the method checks its range when built).
    Number {
        /// The panel's least value.
        min: f32,
        /// The panel's largest value.
        max: f32,
    },
    /// Off (0) or on (anything else): a checkbox.
    Toggle,
}

impl Slider {
    /// A whole-number slider taken in place while dragging.
    pub const fn count(
        name: &'static str,
        label: &'static str,
        (min, max): (u32, u32),
        get: fn(&MethodSettings) -> f32,
        put: fn(&mut MethodSettings, f32),
    ) -> Slider {
        Slider {
            name,
            label,
            kind: SliderKind::Count { min, max },
            get,
            put,
            live: true,
        }
    }

    /// Write `value` (counts must be whole and positive; each method checks
    /// its own range when built).
    pub fn set(&self, settings: &mut MethodSettings, value: f32) -> anyhow::Result<()> {
        if !value.is_finite() {
            bail!("{value} is not a number");
        }
        match self.kind {
            SliderKind::Count { .. } if !(value >= 1.0 && value.fract() == 0.0 && value <= 1e6) => {
                bail!("{value} is not a positive whole number")
            }
            SliderKind::Toggle => (self.put)(settings, if value != 0.0 { 1.0 } else { 0.0 }),
            _ => (self.put)(settings, value),
        }
        Ok(())
    }
}

/// One command-line flag of `strata render` (`--ray-steps N`).
pub struct Flag {
    /// The flag without its dashes.
    pub long: &'static str,
    /// The value's name in the help (`N`); `None`: a switch without a value.
    pub value: Option<&'static str>,
    /// The help line.
    pub help: &'static str,
    /// The default as the help shows it (switches: unused).
    pub default: fn(&MethodSettings) -> String,
    /// Write the flag's value (a switch: `"true"`) into the settings.
    pub apply: fn(&str, &mut MethodSettings) -> Result<(), String>,
}

/// A method's sweep in `strata tune`, in `name:SETTING` form.
pub struct Sweep {
    /// Where the method stands in the tuning report (ascending).
    pub order: u8,
    /// What the knob is, for the report's table (`steps`).
    pub knob: &'static str,
    /// The full sweep; empty for a method without a knob (one point).
    pub full: &'static [&'static str],
    /// `--quick`'s fewer points (always the ends and the default).
    pub quick: &'static [&'static str],
    /// Also swept at the paper's picture size (the mesh).
    pub at_paper_size: bool,
}

/// A whole number of at least 1.
pub fn count(text: &str) -> Result<u32, String> {
    match text.trim().parse::<u32>() {
        Ok(v) if v > 0 => Ok(v),
        Ok(_) => Err("must be a positive whole number, at least 1 (got 0)".into()),
        Err(_) => Err(format!("`{}` is not a positive whole number", text.trim())),
    }
}

/// A finite number above 0.
pub fn positive(text: &str) -> Result<f32, String> {
    match text.trim().parse::<f32>() {
        Ok(v) if v.is_finite() && v > 0.0 => Ok(v),
        _ => Err(format!("`{}` is not a positive number", text.trim())),
    }
}

/// `X,Y,Z` of whole numbers of at least 1 (`what`: for the message).
pub fn count_triple(text: &str, what: &str) -> Result<[u32; 3], String> {
    let parts: Vec<&str> = text.split(',').collect();
    let [x, y, z] = parts[..] else {
        return Err(format!(
            "`{text}` is not X,Y,Z (three {what}s in texels, e.g. 4,8,2)"
        ));
    };
    let one = |t| count(t).map_err(|e| format!("{what} {e}"));
    Ok([one(x)?, one(y)?, one(z)?])
}

/// `X,Y,Z` or one `D` for all three, each a positive number.
pub fn number_triple(text: &str, what: &str) -> Result<[f32; 3], String> {
    let v = text
        .split(',')
        .map(|t| positive(t).map_err(|e| format!("{what} {e}")))
        .collect::<Result<Vec<_>, _>>()?;
    match v[..] {
        [d] => Ok([d; 3]),
        [x, y, z] => Ok([x, y, z]),
        _ => Err(format!(
            "`{text}` is not X,Y,Z or D (samples per unit, e.g. 4,4,4)"
        )),
    }
}

/// `a,b,c` as the help shows a triple.
pub fn show_triple<T: std::fmt::Display>(v: &[T; 3]) -> String {
    let [x, y, z] = v;
    format!("{x},{y},{z}")
}

/// A `String` error as an `anyhow` one.
pub fn plain<T>(r: Result<T, String>) -> anyhow::Result<T> {
    r.map_err(anyhow::Error::msg)
}
