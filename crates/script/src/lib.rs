//! `--script FILE`: the viewer driven without a person, for tests, demos and
//! reproducible screenshots. One command per line; `#` starts a comment.
//! Commands run in order through the real window and event loop, one frame
//! (or the stated number of frames) each:
//!
//! ```text
//! view NAME                 jump to one of the level's named views
//! method NAME               switch the method (waits while it is built)
//! split NAME | split off    A/B: the current method left, NAME right
//! fly F R U [FRAMES]        move F units along the view, R to the screen's right, U up
//! goto X Y                  fly to (X, Y) at the same height above the ground (a map click)
//! turn RIGHT UP [FRAMES]    turn, degrees
//! frames N                  render N frames
//! dig X Y                   click at (X, Y) of the picture, fractions 0..1 (0.5 0.5 = centre)
//! undo                      undo the last dig
//! physics on|off            the physics toy (on: waits until its collider is fitted)
//! drop ball|box X Y         drop a body where picture point (X, Y) shows terrain (fractions)
//! clear-bodies              remove the physics toy's bodies
//! save DIR                  save the edited world as a world directory (see `save`)
//! set KNOB VALUE            ray-steps, voxel-steps, slices, density, mesh-quality, shadows (0/1)
//! overlay on|off            show or hide the overlay
//! window W H                resize the window (the picture follows)
//! screenshot PATH           save what the window shows as PNG
//! copy-view [NAME]          print the current view as a views.txt line
//! score                     print the drawn method(s)' metrics against the CPU reference
//! memory                    print a `memory …` line: process RSS, the renderer's GPU and
//!                           CPU bytes (shared + kept methods), undo bytes (the soak)
//! lose-device               destroy the GPU device, as a driver reset would (tests
//!                           that the edits are saved to OUT/<world>-recovered)
//! quit                      stop here (the end of the file does too)
//! ```
//!
//! The language is the viewer's, without the window: the viewer
//! (`strata_viewer::script`) reads `set`'s names as its own knobs
//! ([`Setting`]) and `drop`'s bodies as its physics toy's (`From<`[`Body`]`>`);
//! the fuzzer (`strata-fuzz`) parses with any name ([`String`]) and [`Body`].
//! No GPU, window or UI dependency.

#![warn(missing_docs)]

use anyhow::{Context, bail};
use std::path::{Path, PathBuf};

/// What a script's `set` names: the host's settings, parsed from their names.
pub trait Setting: Sized {
    /// The setting called `name`, or an error naming the known ones.
    fn parse(name: &str) -> anyhow::Result<Self>;
}

/// Any name is a setting (for a reader that checks names later, or never).
impl Setting for String {
    fn parse(name: &str) -> anyhow::Result<String> {
        Ok(name.to_string())
    }
}

/// The body `drop` names.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Body {
    /// `drop ball`.
    Ball,
    /// `drop box`.
    Box,
}

/// One script command; `K` is the host's setting type, `D` its body type.
#[allow(missing_docs)] // each variant is its line in the table above
#[derive(Clone, Debug, PartialEq)]
pub enum Command<K = String, D = Body> {
    View(String),
    Method(String),
    Split(Option<String>),
    /// Offset in camera terms (forward, right, up), spread over `frames`.
    Fly {
        offset: [f32; 3],
        frames: u32,
    },
    /// Degrees (right, up), spread over `frames`.
    Turn {
        degrees: [f32; 2],
        frames: u32,
    },
    Frames(u32),
    /// World x, y.
    Goto(f32, f32),
    /// Fractions of the picture's width and height.
    Dig(f32, f32),
    Undo,
    /// The physics toy on or off.
    Physics(bool),
    /// A body dropped at fractions of the picture's width and height.
    Drop(D, f32, f32),
    ClearBodies,
    /// A world directory to save the edited world into.
    Save(PathBuf),
    Set(K, f32),
    Overlay(bool),
    /// Window inner size, pixels.
    Window(u32, u32),
    Screenshot(PathBuf),
    CopyView(String),
    Score,
    Memory,
    LoseDevice,
    Quit,
}

/// A parsed script with each command's line number, for messages.
#[derive(Clone, Debug, PartialEq)]
pub struct Script<K = String, D = Body> {
    /// (line number, command), in order.
    pub commands: Vec<(usize, Command<K, D>)>,
}

// Not derived: a derive would ask `K: Default` and `D: Default`.
impl<K, D> Default for Script<K, D> {
    fn default() -> Self {
        Script {
            commands: Vec::new(),
        }
    }
}

impl<K: Setting, D: From<Body>> Script<K, D> {
    /// Read and parse a script file; errors name the file and the line.
    pub fn load(path: &Path) -> anyhow::Result<Self> {
        let text = std::fs::read_to_string(path)
            .with_context(|| format!("reading the script {}", path.display()))?;
        Script::parse(&text).with_context(|| format!("in the script {}", path.display()))
    }

    /// `--frames N --screenshot PATH` as a script.
    pub fn frames_then_screenshot(frames: u32, screenshot: Option<PathBuf>) -> Self {
        let mut commands = vec![(0, Command::Frames(frames))];
        if let Some(path) = screenshot {
            commands.push((0, Command::Screenshot(path)));
        }
        Script { commands }
    }

    /// Parse a script's text; errors name the line and the reason.
    pub fn parse(text: &str) -> anyhow::Result<Self> {
        let mut commands = Vec::new();
        for (i, raw) in text.lines().enumerate() {
            let line = raw.split('#').next().unwrap_or("").trim();
            if line.is_empty() {
                continue;
            }
            let command = parse_line(line).with_context(|| format!("line {}: `{line}`", i + 1))?;
            commands.push((i + 1, command));
        }
        Ok(Script { commands })
    }
}

fn number<T: std::str::FromStr>(text: &str, what: &str) -> anyhow::Result<T> {
    text.parse()
        .map_err(|_| anyhow::anyhow!("{what} `{text}` is not a number"))
}

fn finite(text: &str, what: &str) -> anyhow::Result<f32> {
    let v: f32 = number(text, what)?;
    if !v.is_finite() {
        bail!("{what} must be finite");
    }
    Ok(v)
}

/// Frames of an optional trailing count: at least one.
fn frames_arg(arg: Option<&&str>) -> anyhow::Result<u32> {
    match arg {
        None => Ok(1),
        Some(t) => match number::<u32>(t, "frame count")? {
            0 => bail!("frame count must be at least 1"),
            n => Ok(n),
        },
    }
}

fn parse_line<K: Setting, D: From<Body>>(line: &str) -> anyhow::Result<Command<K, D>> {
    let words: Vec<&str> = line.split_whitespace().collect();
    let args = &words[1..];
    let arity = |min: usize, max: usize| -> anyhow::Result<()> {
        if args.len() < min || args.len() > max {
            bail!(
                "`{}` takes {} argument(s), got {}",
                words[0],
                if min == max {
                    min.to_string()
                } else {
                    format!("{min} to {max}")
                },
                args.len()
            );
        }
        Ok(())
    };
    Ok(match words[0] {
        "view" => {
            arity(1, 1)?;
            Command::View(args[0].to_string())
        }
        "method" => {
            arity(1, 1)?;
            Command::Method(args[0].to_string())
        }
        "split" => {
            arity(1, 1)?;
            Command::Split((args[0] != "off").then(|| args[0].to_string()))
        }
        "fly" => {
            arity(3, 4)?;
            Command::Fly {
                offset: [
                    finite(args[0], "forward")?,
                    finite(args[1], "right")?,
                    finite(args[2], "up")?,
                ],
                frames: frames_arg(args.get(3))?,
            }
        }
        "turn" => {
            arity(2, 3)?;
            Command::Turn {
                degrees: [finite(args[0], "right")?, finite(args[1], "up")?],
                frames: frames_arg(args.get(2))?,
            }
        }
        "goto" => {
            arity(2, 2)?;
            Command::Goto(finite(args[0], "x")?, finite(args[1], "y")?)
        }
        "frames" => {
            arity(1, 1)?;
            Command::Frames(frames_arg(args.first())?)
        }
        "dig" => {
            arity(2, 2)?;
            let (x, y) = (finite(args[0], "x")?, finite(args[1], "y")?);
            if !(0.0..=1.0).contains(&x) || !(0.0..=1.0).contains(&y) {
                bail!("dig takes fractions of the picture, 0..1");
            }
            Command::Dig(x, y)
        }
        "undo" => {
            arity(0, 0)?;
            Command::Undo
        }
        "save" => {
            arity(1, 1)?;
            Command::Save(PathBuf::from(args[0]))
        }
        "set" => {
            arity(2, 2)?;
            Command::Set(K::parse(args[0])?, finite(args[1], "value")?)
        }
        "physics" => {
            arity(1, 1)?;
            match args[0] {
                "on" => Command::Physics(true),
                "off" => Command::Physics(false),
                other => bail!("physics takes on or off, not `{other}`"),
            }
        }
        "drop" => {
            arity(3, 3)?;
            let what = match args[0] {
                "ball" => Body::Ball,
                "box" => Body::Box,
                other => bail!("drop takes ball or box, not `{other}`"),
            };
            let (x, y) = (finite(args[1], "x")?, finite(args[2], "y")?);
            if !(0.0..=1.0).contains(&x) || !(0.0..=1.0).contains(&y) {
                bail!("drop takes fractions of the picture, 0..1");
            }
            Command::Drop(what.into(), x, y)
        }
        "clear-bodies" => {
            arity(0, 0)?;
            Command::ClearBodies
        }
        "overlay" => {
            arity(1, 1)?;
            match args[0] {
                "on" => Command::Overlay(true),
                "off" => Command::Overlay(false),
                other => bail!("overlay takes on or off, not `{other}`"),
            }
        }
        "window" => {
            arity(2, 2)?;
            let side = |t: &str| -> anyhow::Result<u32> {
                match number::<u32>(t, "window size")? {
                    v @ 1..=16384 => Ok(v),
                    _ => bail!("window sides are 1..=16384 pixels"),
                }
            };
            Command::Window(side(args[0])?, side(args[1])?)
        }
        "screenshot" => {
            arity(1, 1)?;
            Command::Screenshot(PathBuf::from(args[0]))
        }
        "copy-view" => {
            arity(0, 1)?;
            Command::CopyView(args.first().unwrap_or(&"viewer").to_string())
        }
        "score" => {
            arity(0, 0)?;
            Command::Score
        }
        "memory" => {
            arity(0, 0)?;
            Command::Memory
        }
        "lose-device" => {
            arity(0, 0)?;
            Command::LoseDevice
        }
        "quit" => {
            arity(0, 0)?;
            Command::Quit
        }
        other => bail!(
            "unknown command `{other}` (view, method, split, fly, goto, turn, frames, dig, undo, \
             save, set, overlay, window, screenshot, copy-view, score, memory, lose-device, quit)"
        ),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_the_physics_commands_and_names_bad_ones() {
        let script: Script =
            Script::parse("physics on\ndrop box 0.25 0.5\nclear-bodies\nphysics off").unwrap();
        let commands: Vec<_> = script.commands.into_iter().map(|(_, c)| c).collect();
        assert_eq!(
            commands,
            [
                Command::Physics(true),
                Command::Drop(Body::Box, 0.25, 0.5),
                Command::ClearBodies,
                Command::Physics(false)
            ]
        );
        for (bad, says) in [
            ("drop ball 2 0.5", "fractions"),
            ("drop car 0.5 0.5", "`car`"),
            ("physics maybe", "`maybe`"),
        ] {
            let e = format!("{:#}", Script::<String>::parse(bad).unwrap_err());
            assert!(e.contains(says), "{bad}: {e}");
        }
    }

    #[test]
    fn parses_every_command() {
        let script: Script = Script::parse(
            "# a flight\nview hangar\nmethod mesh  # switch\nsplit ray\nsplit off\n\
             fly 10 -2 3 5\ngoto 100 2000\nturn 15 -5\nframes 4\ndig 0.5 0.25\nundo\nsave out/w\nset ray-steps 64\n\
             overlay off\nwindow 640 480\nscreenshot out/a.png\ncopy-view\nscore\nmemory\nlose-device\nquit\n",
        )
        .unwrap();
        let commands: Vec<_> = script.commands.iter().map(|(_, c)| c.clone()).collect();
        assert_eq!(
            commands,
            vec![
                Command::View("hangar".into()),
                Command::Method("mesh".into()),
                Command::Split(Some("ray".into())),
                Command::Split(None),
                Command::Fly {
                    offset: [10.0, -2.0, 3.0],
                    frames: 5
                },
                Command::Goto(100.0, 2000.0),
                Command::Turn {
                    degrees: [15.0, -5.0],
                    frames: 1
                },
                Command::Frames(4),
                Command::Dig(0.5, 0.25),
                Command::Undo,
                Command::Save("out/w".into()),
                Command::Set("ray-steps".to_string(), 64.0),
                Command::Overlay(false),
                Command::Window(640, 480),
                Command::Screenshot("out/a.png".into()),
                Command::CopyView("viewer".into()),
                Command::Score,
                Command::Memory,
                Command::LoseDevice,
                Command::Quit,
            ]
        );
        assert_eq!(script.commands[0].0, 2, "line numbers count comments");
    }

    #[test]
    fn bad_lines_name_their_line_and_reason() {
        for (text, needle) in [
            ("frames 2\nwalk 3", "line 2"),
            ("dig 1.5 0.5", "fractions"),
            ("fly 1 2", "3 to 4"),
            ("frames 0", "at least 1"),
            ("set", "2 argument(s), got 0"),
            ("turn nan 2", "finite"),
            ("overlay maybe", "on or off"),
            ("window 0 100", "1..=16384"),
        ] {
            let err = format!("{:#}", Script::<String>::parse(text).unwrap_err());
            assert!(err.contains(needle), "`{text}` gave `{err}`");
        }
    }

    /// A host whose one setting is `speed` and whose bodies are numbers.
    #[derive(Clone, Copy, Debug, PartialEq)]
    struct Speed;

    impl Setting for Speed {
        fn parse(name: &str) -> anyhow::Result<Speed> {
            match name {
                "speed" => Ok(Speed),
                _ => bail!("unknown setting `{name}`; known: speed"),
            }
        }
    }

    #[derive(Clone, Copy, Debug, PartialEq)]
    struct Shape(u8);

    impl From<Body> for Shape {
        fn from(b: Body) -> Shape {
            Shape(b as u8)
        }
    }

    #[test]
    fn set_and_drop_speak_the_hosts_types() {
        let script = Script::<Speed, Shape>::parse("set speed 2\ndrop box 0.5 0.5").unwrap();
        assert_eq!(
            script.commands,
            [
                (1, Command::Set(Speed, 2.0)),
                (2, Command::Drop(Shape(Body::Box as u8), 0.5, 0.5))
            ]
        );
        let err = format!(
            "{:#}",
            Script::<Speed, Shape>::parse("frames 1\nset warp 3").unwrap_err()
        );
        assert!(
            err.contains("line 2") && err.contains("unknown setting `warp`"),
            "{err}"
        );
        assert_eq!(Script::<Speed, Shape>::default().commands, []);
    }
}
