//! `--script FILE`: the viewer driven without a person. The language (its
//! commands and parser) lives in `strata-script`, GPU-free so that it is
//! fuzzed without a window; here `set` names the viewer's [`Knob`]s and
//! `drop` the physics toy's bodies.

use crate::knobs::Knob;
use crate::physics::Drop;
pub use strata_script::{Body, Setting};

/// A parsed script of the viewer's commands.
pub type Script = strata_script::Script<Knob, Drop>;
/// One command of a [`Script`].
pub type Command = strata_script::Command<Knob, Drop>;

impl Setting for Knob {
    fn parse(name: &str) -> anyhow::Result<Knob> {
        Knob::parse(name)
    }
}

impl From<Body> for Drop {
    fn from(body: Body) -> Drop {
        match body {
            Body::Ball => Drop::Sphere,
            Body::Box => Drop::Box,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn set_names_a_knob_and_drop_a_physics_body() {
        let script = Script::parse("set ray-steps 64\ndrop ball 0.5 0.5").unwrap();
        assert_eq!(
            script.commands,
            [
                (1, Command::Set(Knob::parse("ray-steps").unwrap(), 64.0)),
                (2, Command::Drop(Drop::Sphere, 0.5, 0.5))
            ]
        );
        let err = format!("{:#}", Script::parse("set warp 3").unwrap_err());
        assert!(err.contains("unknown setting"), "{err}");
    }
}
