//! Named camera views (`views.txt`) and the edit fixture (`edit.txt`).
//!
//! `views.txt`, one view per line, `#` starts a comment:
//! `NAME X,Y:YAW:EYE[:under] PITCH` — yaw and pitch in degrees, the eye
//! height above the top surface at (X, Y), or above the floor with `under`.
//! The same format is accepted by `--views FILE` everywhere.

use serde::{Deserialize, Serialize};
use std::fmt;

/// Where a camera stands and looks, before it is resolved against a level.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ViewSpec {
    /// Name in reports and output directories.
    pub name: String,
    /// Eye x, texels; wrapped onto the map when resolved.
    pub x: f32,
    /// Eye y, texels; wrapped onto the map when resolved.
    pub y: f32,
    /// Degrees; yaw 0 looks along +y, yaw 90 along +x.
    pub yaw: f32,
    /// Eye height above the top surface (or the floor, when `under`).
    pub eye: f32,
    /// Measure `eye` from the floor instead of the top surface (inside caves).
    pub under: bool,
    /// Degrees in [-90, 90]; negative looks down.
    pub pitch: f32,
}

/// Why a view or edit fixture does not parse.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum ViewError {
    /// A line of `views.txt` or `edit.txt` has the wrong shape.
    #[error("line {line}: {msg} (expected `NAME X,Y:YAW:EYE[:under] PITCH`)")]
    Malformed {
        /// 1-based line number (0 when the whole file is at fault).
        line: usize,
        /// What is wrong.
        msg: String,
    },
    /// The position part `X,Y:YAW:EYE[:under]` does not parse.
    #[error("`{spec}`: {msg} (expected `X,Y:YAW:EYE[:under]`)")]
    Spec {
        /// The text given.
        spec: String,
        /// What is wrong.
        msg: String,
    },
    /// The pitch (degrees) is outside [-90, 90].
    #[error("pitch {0} is outside [-90, 90] degrees")]
    Pitch(f32),
}

fn number(text: &str, what: &str, spec: &str) -> Result<f32, ViewError> {
    let v: f32 = text.trim().parse().map_err(|_| ViewError::Spec {
        spec: spec.to_string(),
        msg: format!("{what} `{text}` is not a number"),
    })?;
    if !v.is_finite() {
        return Err(ViewError::Spec {
            spec: spec.to_string(),
            msg: format!("{what} must be finite"),
        });
    }
    Ok(v)
}

/// Check a pitch in degrees.
pub fn check_pitch(pitch: f32) -> Result<f32, ViewError> {
    if (-90.0..=90.0).contains(&pitch) {
        Ok(pitch)
    } else {
        Err(ViewError::Pitch(pitch))
    }
}

impl ViewSpec {
    /// Parse the position part `X,Y:YAW:EYE[:under]` and combine it with a pitch.
    pub fn parse(name: &str, spec: &str, pitch: f32) -> Result<Self, ViewError> {
        let err = |msg: &str| ViewError::Spec {
            spec: spec.to_string(),
            msg: msg.to_string(),
        };
        let parts: Vec<&str> = spec.split(':').collect();
        if !(3..=4).contains(&parts.len()) {
            return Err(err("needs three or four `:`-separated fields"));
        }
        let (x, y) = parts[0]
            .split_once(',')
            .ok_or_else(|| err("position must be `X,Y`"))?;
        let under = match parts.get(3) {
            None => false,
            Some(&"under") => true,
            Some(other) => return Err(err(&format!("unknown flag `{other}`, only `under`"))),
        };
        Ok(ViewSpec {
            name: name.to_string(),
            x: number(x, "x", spec)?,
            y: number(y, "y", spec)?,
            yaw: number(parts[1], "yaw", spec)?,
            eye: number(parts[2], "eye", spec)?,
            under,
            pitch: check_pitch(pitch)?,
        })
    }

    /// The position part, as `parse` reads it.
    pub fn spec_string(&self) -> String {
        let under = if self.under { ":under" } else { "" };
        format!("{},{}:{}:{}{}", self.x, self.y, self.yaw, self.eye, under)
    }
}

impl fmt::Display for ViewSpec {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{} {} {}", self.name, self.spec_string(), self.pitch)
    }
}

/// Parse a views file. Blank lines and `#` comments are skipped.
pub fn parse_views(text: &str) -> Result<Vec<ViewSpec>, ViewError> {
    let mut views = Vec::new();
    for (i, raw) in text.lines().enumerate() {
        let line = raw.split('#').next().unwrap_or("").trim();
        if line.is_empty() {
            continue;
        }
        let malformed = |msg: String| ViewError::Malformed { line: i + 1, msg };
        let fields: Vec<&str> = line.split_whitespace().collect();
        if fields.len() != 3 {
            return Err(malformed(format!("{} fields, expected 3", fields.len())));
        }
        let pitch: f32 = fields[2]
            .parse()
            .map_err(|_| malformed(format!("pitch `{}` is not a number", fields[2])))?;
        let view =
            ViewSpec::parse(fields[0], fields[1], pitch).map_err(|e| malformed(e.to_string()))?;
        views.push(view);
    }
    Ok(views)
}

/// Write views in the format [`parse_views`] reads.
pub fn format_views(views: &[ViewSpec]) -> String {
    let mut out =
        String::from("# NAME X,Y:YAW:EYE[:under] PITCH (degrees; eye above the top surface)\n");
    for v in views {
        out.push_str(&v.to_string());
        out.push('\n');
    }
    out
}

/// The level's edit fixture: a crater and the camera that times it.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct EditSite {
    /// Crater centre x, texels (any value; wraps).
    pub centre_x: i64,
    /// Crater centre y, texels (any value; wraps).
    pub centre_y: i64,
    /// Crater radius, texels.
    pub radius: u32,
    /// Depth at the centre; the crater profile is `depth (1 - d²/r²)`.
    pub depth: f32,
    /// The view that watches the crater being dug.
    pub camera: ViewSpec,
}

impl EditSite {
    /// The paper's fixture for Fostral (DESIGN §2).
    pub fn fostral() -> Self {
        EditSite {
            centre_x: 1024,
            centre_y: 8192,
            radius: 48,
            depth: 90.0,
            camera: ViewSpec {
                name: "edit".into(),
                x: 1024.0,
                y: 8350.0,
                yaw: 180.0,
                eye: 40.0,
                under: false,
                pitch: -30.0,
            },
        }
    }

    /// `edit.txt`: `crater X,Y RADIUS DEPTH` and `camera X,Y:YAW:EYE[:under] PITCH`.
    pub fn parse(text: &str) -> Result<Self, ViewError> {
        let mut crater = None;
        let mut camera = None;
        for (i, raw) in text.lines().enumerate() {
            let line = raw.split('#').next().unwrap_or("").trim();
            if line.is_empty() {
                continue;
            }
            let malformed = |msg: &str| ViewError::Malformed {
                line: i + 1,
                msg: msg.to_string(),
            };
            let fields: Vec<&str> = line.split_whitespace().collect();
            match fields.as_slice() {
                ["crater", pos, radius, depth] => {
                    let (x, y) = pos
                        .split_once(',')
                        .ok_or_else(|| malformed("crater position must be X,Y"))?;
                    let parse_i = |t: &str| {
                        t.parse::<i64>()
                            .map_err(|_| malformed("crater position must be integers"))
                    };
                    let radius: u32 = radius
                        .parse()
                        .map_err(|_| malformed("crater radius must be a positive integer"))?;
                    let depth: f32 = depth
                        .parse()
                        .map_err(|_| malformed("crater depth must be a number"))?;
                    if radius == 0 || !depth.is_finite() {
                        return Err(malformed("crater radius must be > 0 and depth finite"));
                    }
                    crater = Some((parse_i(x)?, parse_i(y)?, radius, depth));
                }
                ["camera", spec, pitch] => {
                    let pitch: f32 = pitch
                        .parse()
                        .map_err(|_| malformed("camera pitch must be a number"))?;
                    camera = Some(
                        ViewSpec::parse("edit", spec, pitch)
                            .map_err(|e| malformed(&e.to_string()))?,
                    );
                }
                _ => {
                    return Err(malformed(
                        "expected `crater X,Y RADIUS DEPTH` or `camera SPEC PITCH`",
                    ));
                }
            }
        }
        match (crater, camera) {
            (Some((centre_x, centre_y, radius, depth)), Some(camera)) => Ok(EditSite {
                centre_x,
                centre_y,
                radius,
                depth,
                camera,
            }),
            _ => Err(ViewError::Malformed {
                line: 0,
                msg: "edit file needs both a `crater` and a `camera` line".into(),
            }),
        }
    }

    /// The `edit.txt` text that [`EditSite::parse`] reads back.
    pub fn format(&self) -> String {
        format!(
            "# crater X,Y RADIUS DEPTH  (profile depth * (1 - d^2/r^2), upper layer removed inside)\n\
             crater {},{} {} {}\n\
             # camera X,Y:YAW:EYE[:under] PITCH\n\
             camera {} {}\n",
            self.centre_x,
            self.centre_y,
            self.radius,
            self.depth,
            self.camera.spec_string(),
            self.camera.pitch
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn views_round_trip() {
        let text = "# Fostral\nriver 837,3984:299:78 0\n\ncave 10.5,20:90:3:under -30 # inside\n";
        let views = parse_views(text).unwrap();
        assert_eq!(views.len(), 2);
        assert_eq!(views[0].name, "river");
        assert_eq!(
            (views[0].x, views[0].y, views[0].yaw, views[0].eye),
            (837.0, 3984.0, 299.0, 78.0)
        );
        assert!(views[1].under && views[1].pitch == -30.0);
        assert_eq!(parse_views(&format_views(&views)).unwrap(), views);
    }

    #[test]
    fn malformed_views_name_the_line() {
        for bad in [
            "a 1,2:3 0",
            "a 1;2:3:4 0",
            "a 1,2:3:4 x",
            "a 1,2:3:4:over 0",
            "a 1,2:3:4 -91",
            "a 1,2:3:4",
        ] {
            let err = parse_views(&format!("ok 1,2:3:4 0\n{bad}\n")).unwrap_err();
            assert!(
                matches!(err, ViewError::Malformed { line: 2, .. }),
                "{bad}: {err}"
            );
        }
    }

    #[test]
    fn edit_site_round_trips() {
        let site = EditSite::fostral();
        assert_eq!(EditSite::parse(&site.format()).unwrap(), site);
        assert!(EditSite::parse("crater 1,2 48 90\n").is_err());
    }
}
