//! Camera paths: keyframes read from a file (or the default fly-through) and
//! the smooth camera between them.
//!
//! A path file has one keyframe per line, `X,Y:YAW:EYE[:under] PITCH TIME`
//! (the views file's position and pitch, then the time in seconds), and at
//! most one `dig TIME` line: the level's crater is dug at that time. `#`
//! starts a comment.

use glam::Vec3;
use std::fmt;
use strata_camera::Camera;
use strata_level::model::Column;
use strata_level::source::ColumnSource;
use strata_level::{EditSite, ViewSpec, World};

/// What a path file line can be wrong about; every message names the line.
#[derive(Debug, PartialEq)]
pub enum PathError {
    Malformed {
        line: usize,
        msg: String,
    },
    TooFewKeyframes(usize),
    /// A keyframe's eye is inside solid terrain (or its view is otherwise unusable).
    Keyframe {
        line: usize,
        msg: String,
    },
}

impl fmt::Display for PathError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            PathError::Malformed { line, msg } => write!(
                f,
                "line {line}: {msg} (expected `X,Y:YAW:EYE[:under] PITCH TIME` or `dig TIME`)"
            ),
            PathError::TooFewKeyframes(n) => write!(
                f,
                "a camera path needs at least two keyframes; this one has {n}"
            ),
            PathError::Keyframe { line: 0, msg } => write!(f, "the built-in path: {msg}"),
            PathError::Keyframe { line, msg } => write!(f, "line {line}: {msg}"),
        }
    }
}

impl std::error::Error for PathError {}

/// One keyframe as written: a view and the time it is reached.
#[derive(Clone, Debug, PartialEq)]
pub struct Keyframe {
    pub view: ViewSpec,
    pub time: f32,
    /// Line in the path file (1-based; 0 for built-in paths).
    pub line: usize,
}

/// A parsed path: keyframes in time order and an optional dig time.
#[derive(Clone, Debug, PartialEq)]
pub struct CameraPath {
    pub keys: Vec<Keyframe>,
    pub dig_at: Option<f32>,
}

impl CameraPath {
    /// Parse a path file's text.
    pub fn parse(text: &str) -> Result<CameraPath, PathError> {
        let mut keys: Vec<Keyframe> = Vec::new();
        let mut dig_at = None;
        let mut dig_line = 0;
        for (i, raw) in text.lines().enumerate() {
            let line = i + 1;
            let body = raw.split('#').next().unwrap_or("").trim();
            if body.is_empty() {
                continue;
            }
            let bad = |msg: String| PathError::Malformed { line, msg };
            let fields: Vec<&str> = body.split_whitespace().collect();
            let time = |text: &str| -> Result<f32, PathError> {
                match text.parse::<f32>() {
                    Ok(t) if t.is_finite() && t >= 0.0 => Ok(t),
                    _ => Err(bad(format!(
                        "time `{text}` is not a non-negative number of seconds"
                    ))),
                }
            };
            if fields[0] == "dig" {
                if fields.len() != 2 {
                    return Err(bad("`dig` takes one time".into()));
                }
                if dig_at.is_some() {
                    return Err(bad("a second `dig` line (a path digs once)".into()));
                }
                dig_at = Some(time(fields[1])?);
                dig_line = line;
                continue;
            }
            if fields.len() != 3 {
                return Err(bad(format!("{} fields, expected 3", fields.len())));
            }
            let pitch: f32 = fields[1]
                .parse()
                .map_err(|_| bad(format!("pitch `{}` is not a number", fields[1])))?;
            let view = ViewSpec::parse(&format!("key{line}"), fields[0], pitch)
                .map_err(|e| bad(e.to_string()))?;
            let t = time(fields[2])?;
            if let Some(prev) = keys.last()
                && t <= prev.time
            {
                return Err(bad(format!(
                    "time {t} does not come after the previous keyframe's {} (line {})",
                    prev.time, prev.line
                )));
            }
            keys.push(Keyframe {
                view,
                time: t,
                line,
            });
        }
        let path = CameraPath { keys, dig_at };
        if path.keys.len() < 2 {
            return Err(PathError::TooFewKeyframes(path.keys.len()));
        }
        if let Some(t) = path.dig_at
            && (t < path.start() || t > path.end())
        {
            return Err(PathError::Malformed {
                line: dig_line,
                msg: format!(
                    "dig time {t} is outside the keyframes' {}..{} s",
                    path.start(),
                    path.end()
                ),
            });
        }
        Ok(path)
    }

    pub fn start(&self) -> f32 {
        self.keys.first().map_or(0.0, |k| k.time)
    }

    pub fn end(&self) -> f32 {
        self.keys.last().map_or(0.0, |k| k.time)
    }

    /// The same path played in `seconds` (every time scaled, starting at 0).
    pub fn retimed(&self, seconds: f32) -> CameraPath {
        let (t0, span) = (self.start(), (self.end() - self.start()).max(1e-6));
        let scale = |t: f32| (t - t0) / span * seconds;
        CameraPath {
            keys: self
                .keys
                .iter()
                .map(|k| Keyframe {
                    time: scale(k.time),
                    ..k.clone()
                })
                .collect(),
            dig_at: self.dig_at.map(scale),
        }
    }

    /// The path in the file format [`CameraPath::parse`] reads.
    pub fn to_text(&self) -> String {
        let mut out = String::from("# X,Y:YAW:EYE[:under] PITCH TIME (seconds); dig TIME\n");
        for k in &self.keys {
            out.push_str(&format!(
                "{} {} {}\n",
                k.view.spec_string(),
                k.view.pitch,
                k.time
            ));
        }
        if let Some(t) = self.dig_at {
            out.push_str(&format!("dig {t}\n"));
        }
        out
    }

    /// Resolve every keyframe against the ground (the eye's altitude), ready
    /// to sample: a level in memory, or a store read chunk by chunk.
    pub fn resolve(&self, ground: &dyn ColumnSource) -> Result<Flight, PathError> {
        let mut poses = Vec::with_capacity(self.keys.len());
        let mut prev_yaw: Option<f32> = None;
        for k in &self.keys {
            let cam = view_camera(ground, &k.view)
                .map_err(|msg| PathError::Keyframe { line: k.line, msg })?;
            // Unwrap yaw so each step turns the short way (350 -> 10 is +20).
            let yaw = match prev_yaw {
                Some(p) => p + (k.view.yaw - p + 180.0).rem_euclid(360.0) - 180.0,
                None => k.view.yaw,
            };
            prev_yaw = Some(yaw);
            // x, y as written (not wrapped), so a path may cross the map's seam.
            poses.push(Pose {
                position: Vec3::new(k.view.x, k.view.y, cam.position.z),
                yaw,
                pitch: k.view.pitch,
            });
        }
        Ok(Flight {
            times: self.keys.iter().map(|k| k.time).collect(),
            poses,
        })
    }
}

/// Where the camera is and where it looks.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Pose {
    /// x, y unwrapped; z absolute altitude.
    pub position: Vec3,
    pub yaw: f32,
    pub pitch: f32,
}

impl Pose {
    fn to_array(self) -> [f32; 5] {
        let p = self.position;
        [p.x, p.y, p.z, self.yaw, self.pitch]
    }

    fn from_array(a: [f32; 5]) -> Pose {
        Pose {
            position: Vec3::new(a[0], a[1], a[2]),
            yaw: a[3],
            pitch: a[4],
        }
    }
}

/// A resolved path: a C1 cubic Hermite curve through the keyframe poses
/// (Catmull-Rom tangents inside, zero at both ends so the flight starts and
/// stops gently).
#[derive(Clone, Debug)]
pub struct Flight {
    times: Vec<f32>,
    poses: Vec<Pose>,
}

impl Flight {
    pub fn duration(&self) -> f32 {
        self.times.last().copied().unwrap_or(0.0) - self.times.first().copied().unwrap_or(0.0)
    }

    pub fn start(&self) -> f32 {
        self.times.first().copied().unwrap_or(0.0)
    }

    fn tangent(&self, i: usize) -> [f32; 5] {
        let n = self.poses.len();
        if i == 0 || i + 1 >= n {
            return [0.0; 5];
        }
        let (a, b) = (self.poses[i - 1].to_array(), self.poses[i + 1].to_array());
        let dt = self.times[i + 1] - self.times[i - 1];
        std::array::from_fn(|c| (b[c] - a[c]) / dt)
    }

    /// The pose at time `t` (clamped to the path's span).
    pub fn pose(&self, t: f32) -> Pose {
        let n = self.times.len();
        let t = t.clamp(self.times[0], self.times[n - 1]);
        let i = self.times[..n - 1]
            .iter()
            .rposition(|&k| k <= t)
            .unwrap_or(0);
        let (t0, t1) = (self.times[i], self.times[i + 1]);
        let h = t1 - t0;
        let s = (t - t0) / h;
        let (p0, p1) = (self.poses[i].to_array(), self.poses[i + 1].to_array());
        let (m0, m1) = (self.tangent(i), self.tangent(i + 1));
        let (s2, s3) = (s * s, s * s * s);
        let h00 = 2.0 * s3 - 3.0 * s2 + 1.0;
        let h10 = s3 - 2.0 * s2 + s;
        let h01 = -2.0 * s3 + 3.0 * s2;
        let h11 = s3 - s2;
        let mut pose = Pose::from_array(std::array::from_fn(|c| {
            h00 * p0[c] + h10 * h * m0[c] + h01 * p1[c] + h11 * h * m1[c]
        }));
        // A cubic can overshoot its keys: keep the pitch a camera accepts.
        pose.pitch = pose.pitch.clamp(-90.0, 90.0);
        pose
    }

    /// The camera at time `t` for a `width` x `height` image: wrapped onto
    /// the map, and lifted out of terrain where the curve cut through it.
    pub fn camera(
        &self,
        ground: &dyn ColumnSource,
        t: f32,
        width: u32,
        height: u32,
    ) -> anyhow::Result<Camera> {
        let pose = self.pose(t);
        let (w, h) = ground.size();
        let x = pose.position.x.rem_euclid(w as f32);
        let y = pose.position.y.rem_euclid(h as f32);
        let z = free_altitude(ground, x, y, pose.position.z)?;
        Ok(Camera::new(
            Vec3::new(x, y, z),
            pose.yaw.rem_euclid(360.0),
            pose.pitch,
            width,
            height,
        )?)
    }
}

/// The column under map point (`x`, `y`) (wrapping; one chunk read from a store).
fn column_at(ground: &dyn ColumnSource, x: f32, y: f32) -> anyhow::Result<Column> {
    ground
        .column(x.floor() as i64, y.floor() as i64)
        .map_err(|e| anyhow::anyhow!("reading the ground at ({x:.0}, {y:.0}): {e}"))
}

/// The camera of `view` over `ground` (one column read), or why not.
fn view_camera(ground: &dyn ColumnSource, view: &ViewSpec) -> Result<Camera, String> {
    let (w, h) = ground.size();
    let (x, y) = (view.x.rem_euclid(w as f32), view.y.rem_euclid(h as f32));
    let column = column_at(ground, x, y).map_err(|e| format!("{e:#}"))?;
    Camera::from_view_over((w, h), |_, _| column, view, 1, 1).map_err(|e| e.to_string())
}

/// `z`, or the nearest altitude above it that is not solid: between two
/// keyframes the curve may dip into the ground or a slab.
fn free_altitude(ground: &dyn ColumnSource, x: f32, y: f32, z: f32) -> anyhow::Result<f32> {
    const CLEARANCE: f32 = 2.0;
    let c = column_at(ground, x, y)?;
    if !c.is_solid(z) {
        return Ok(z);
    }
    let under_slab = f32::from(c.low) + CLEARANCE;
    if z <= f32::from(c.low) && !c.is_solid(under_slab) && under_slab < f32::from(c.mid) {
        return Ok(under_slab);
    }
    Ok(f32::from(c.top()) + CLEARANCE)
}

/// The default fly-through: from the level's nearest landmark view (the
/// generated world's hangar entrance) high over to its edit site (the
/// roofed depot), the edit camera, in under the depot's roof and out, the
/// crater dug, then around and above it. Without an edit site: a flight
/// between the level's first two views.
pub fn default_path(world: &World) -> CameraPath {
    default_path_over(world, &world.level).expect("a level in memory reads every column")
}

/// [`default_path`] over `ground` (the world's map, which `world` need not
/// hold: a store's is read a chunk at a time); fails where a column cannot be read.
pub fn default_path_over(world: &World, ground: &dyn ColumnSource) -> anyhow::Result<CameraPath> {
    Ok(match &world.edit {
        Some(site) => {
            let path = around_edit_site(site);
            let path = match nearest_landmark(ground.size(), world, site) {
                Some(view) => lead_in(&view, path),
                None => path,
            };
            fit_under_slabs(path, ground)?
        }
        None => {
            let keys = world
                .views
                .iter()
                .take(2)
                .enumerate()
                .map(|(i, v)| Keyframe {
                    view: v.clone(),
                    time: 10.0 * i as f32,
                    line: 0,
                })
                .collect();
            CameraPath { keys, dig_at: None }
        }
    })
}

/// Landmark views this far from the crater (map units) make the lead-in.
const LEAD_IN_RANGE: std::ops::Range<f32> = 300.0..3000.0;
/// Seconds from the landmark to the first keyframe around the edit site.
const LEAD_IN_SECONDS: f32 = 5.0;

/// The level's view nearest the crater within [`LEAD_IN_RANGE`], moved to
/// the copy of the map (it wraps) nearest the crater, so the flight is short.
fn nearest_landmark((w, h): (u32, u32), world: &World, site: &EditSite) -> Option<ViewSpec> {
    let (w, h) = (w as f32, h as f32);
    let (cx, cy) = (site.centre_x as f32, site.centre_y as f32);
    let near = |v: &ViewSpec| {
        let dx = (v.x - cx + w / 2.0).rem_euclid(w) - w / 2.0;
        let dy = (v.y - cy + h / 2.0).rem_euclid(h) - h / 2.0;
        ViewSpec {
            x: cx + dx,
            y: cy + dy,
            ..v.clone()
        }
    };
    let dist = |v: &ViewSpec| (v.x - cx).hypot(v.y - cy);
    world
        .views
        .iter()
        .map(near)
        .filter(|v| LEAD_IN_RANGE.contains(&dist(v)) && v.pitch > -89.0)
        .min_by(|a, b| dist(a).total_cmp(&dist(b)))
}

/// Start `path` at `landmark`, rise over the way to its first keyframe, and
/// shift the rest (and the dig) by [`LEAD_IN_SECONDS`].
fn lead_in(landmark: &ViewSpec, mut path: CameraPath) -> CameraPath {
    let Some(first) = path.keys.first().map(|k| k.view.clone()) else {
        return path;
    };
    let (mx, my) = (0.5 * (landmark.x + first.x), 0.5 * (landmark.y + first.y));
    // Yaw 0 looks along +y, 90 along +x.
    let yaw = (first.x - landmark.x)
        .atan2(first.y - landmark.y)
        .to_degrees()
        .rem_euclid(360.0);
    let transit = ViewSpec {
        name: "transit".into(),
        x: mx,
        y: my,
        yaw,
        eye: 180.0,
        under: false,
        pitch: -20.0,
    };
    for k in &mut path.keys {
        k.time += LEAD_IN_SECONDS;
    }
    path.dig_at = path.dig_at.map(|t| t + LEAD_IN_SECONDS);
    let key = |view: ViewSpec, time: f32| Keyframe {
        view,
        time,
        line: 0,
    };
    path.keys.splice(
        0..0,
        [
            key(landmark.clone(), 0.0),
            key(transit, 0.5 * LEAD_IN_SECONDS),
        ],
    );
    path
}

/// Put each `under` keyframe's eye halfway between floor and slab (the
/// headroom differs from level to level); drop one with no slab above it.
fn fit_under_slabs(mut path: CameraPath, ground: &dyn ColumnSource) -> anyhow::Result<CameraPath> {
    let (w, h) = ground.size();
    let mut keys = Vec::with_capacity(path.keys.len());
    for mut k in path.keys {
        if k.view.under {
            let c = column_at(
                ground,
                k.view.x.rem_euclid(w as f32),
                k.view.y.rem_euclid(h as f32),
            )?;
            let headroom = f32::from(c.mid) - f32::from(c.low);
            k.view.eye = headroom / 2.0;
            if !(c.dual && headroom >= 4.0) {
                continue;
            }
        }
        keys.push(k);
    }
    path.keys = keys;
    Ok(path)
}

/// The keyframes of [`default_path`], relative to the crater centre. The
/// depot's roof spans x in centre±37, y in centre-45..centre-4 (the
/// generator's `Kind::Depot`); the two `under` keys sit under it and
/// outside the crater's radius, so they are under a slab before and after
/// the dig.
fn around_edit_site(site: &EditSite) -> CameraPath {
    let (cx, cy) = (site.centre_x as f32, site.centre_y as f32);
    let e = &site.camera;
    let key = |dx: f32, dy: f32, yaw: f32, eye: f32, under: bool, pitch: f32, time: f32| Keyframe {
        view: ViewSpec {
            name: format!("t{time}"),
            x: cx + dx,
            y: cy + dy,
            yaw,
            eye,
            under,
            pitch,
        },
        time,
        line: 0,
    };
    let edit_cam = |time: f32| Keyframe {
        view: ViewSpec {
            name: format!("edit{time}"),
            ..e.clone()
        },
        time,
        line: 0,
    };
    CameraPath {
        keys: vec![
            key(160.0, 300.0, 208.0, 150.0, false, -35.0, 0.0),
            edit_cam(3.0),
            key(-30.0, 45.0, 180.0, 14.0, false, -5.0, 5.0),
            key(-30.0, -40.0, 90.0, 12.0, true, 0.0, 7.0),
            key(28.0, -40.0, 20.0, 12.0, true, 0.0, 8.5),
            edit_cam(10.0),
            edit_cam(12.0),
            key(-150.0, 70.0, 245.0, 80.0, false, -30.0, 15.0),
            key(0.0, 40.0, 180.0, 200.0, false, -75.0, 18.0),
            key(120.0, -80.0, 300.0, 90.0, false, -30.0, 20.0),
        ],
        dig_at: Some(11.0),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use strata_level::Level;

    fn flat() -> Level {
        Level::flat(256, 256, 20, 1).unwrap()
    }

    #[test]
    fn parses_keys_comments_and_dig() {
        let p = CameraPath::parse(
            "# a comment\n10,20:30:40 -30 0\n\n  50,60:350:40:under 0 2.5 # inline\ndig 1\n",
        )
        .unwrap();
        assert_eq!(p.keys.len(), 2);
        assert_eq!(p.keys[1].line, 4);
        assert!(p.keys[1].view.under);
        assert_eq!(p.keys[1].time, 2.5);
        assert_eq!(p.dig_at, Some(1.0));
        // The text form reads back as the same path.
        let again = CameraPath::parse(&p.to_text()).unwrap();
        assert_eq!(again.dig_at, p.dig_at);
        assert_eq!(
            again.keys[1].view.spec_string(),
            p.keys[1].view.spec_string()
        );
    }

    #[test]
    fn malformed_lines_name_their_line() {
        let err = |t: &str| CameraPath::parse(t).unwrap_err().to_string();
        let e = err("1,2:0:10 0 0\n# ok\n1,2:0:10 -30\n");
        assert!(e.starts_with("line 3:"), "{e}");
        assert!(e.contains("2 fields"), "{e}");
        assert!(err("1,2:0:10 0 0\n1,2:0 0 1\n").starts_with("line 2:"));
        assert!(err("1,2:0:10 0 0\n1,2:0:10 abc 1\n").contains("pitch `abc`"));
        assert!(err("1,2:0:10 0 0\n1,2:0:10 0 -1\n").contains("time `-1`"));
        let e = err("1,2:0:10 0 2\n1,2:0:10 0 1\n");
        assert!(e.contains("line 2") && e.contains("after"), "{e}");
        assert!(err("1,2:0:10 0 0\n1,2:0:10 0 1\ndig\n").starts_with("line 3:"));
        assert!(err("1,2:0:10 0 0\n1,2:0:10 0 1\ndig 5\n").contains("outside"));
        assert!(err("1,2:0:10 100 0\n1,2:0:10 0 1\n").contains("pitch 100"));
    }

    #[test]
    fn fewer_than_two_keyframes_is_an_error() {
        assert_eq!(
            CameraPath::parse("# nothing\n"),
            Err(PathError::TooFewKeyframes(0))
        );
        assert_eq!(
            CameraPath::parse("1,2:0:10 0 0\n"),
            Err(PathError::TooFewKeyframes(1))
        );
    }

    #[test]
    fn flight_passes_through_keys_smoothly() {
        let p =
            CameraPath::parse("0,0:0:10 0 0\n100,0:90:20 -30 1\n100,100:180:10 -60 3\n").unwrap();
        let f = p.resolve(&flat()).unwrap();
        // Keys are hit exactly (z = ground 20 + eye).
        let at1 = f.pose(1.0);
        assert!(at1.position.abs_diff_eq(Vec3::new(100.0, 0.0, 40.0), 1e-4));
        assert_eq!((at1.yaw, at1.pitch), (90.0, -30.0));
        let end = f.pose(3.0);
        assert!(
            end.position
                .abs_diff_eq(Vec3::new(100.0, 100.0, 30.0), 1e-4)
        );
        // Zero velocity at the ends, continuous velocity at the inner key.
        let v = |t: f32| (f.pose(t + 1e-3).position - f.pose(t - 1e-3).position) / 2e-3;
        assert!(v(1e-3).length() < 1.0, "{}", v(1e-3));
        let (before, after) = (v(1.0 - 2e-3), v(1.0 + 2e-3));
        assert!((before - after).length() < 2.0, "{before} vs {after}");
        assert!(v(1.0).x > 10.0, "moving on through the middle key");
        // Outside the span: clamped to the ends.
        assert_eq!(f.pose(-5.0), f.pose(0.0));
        assert_eq!(f.pose(9.0), f.pose(3.0));
    }

    #[test]
    fn yaw_turns_the_short_way() {
        let p = CameraPath::parse("0,0:350:10 0 0\n0,0:10:10 0 1\n").unwrap();
        let f = p.resolve(&flat()).unwrap();
        let mid = f.pose(0.5).yaw.rem_euclid(360.0);
        assert!(!(20.0..340.0).contains(&mid), "{mid}");
    }

    #[test]
    fn cameras_wrap_and_stay_out_of_terrain() {
        let level = flat();
        let p = CameraPath::parse("-10,300:0:1 0 0\n-10,300:0:1 0 1\n").unwrap();
        let f = p.resolve(&level).unwrap();
        let c = f.camera(&level, 0.5, 8, 8).unwrap();
        assert_eq!((c.position.x, c.position.y), (246.0, 44.0));
        // An altitude in the ground is lifted above it.
        assert_eq!(free_altitude(&level, 5.0, 5.0, 3.0).unwrap(), 22.0);
        assert_eq!(free_altitude(&level, 5.0, 5.0, 30.0).unwrap(), 30.0);
    }

    #[test]
    fn keyframe_inside_terrain_names_its_line() {
        let p = CameraPath::parse("1,1:0:10 0 0\n1,1:0:-15 0 1\n").unwrap();
        let e = p.resolve(&flat()).unwrap_err().to_string();
        assert!(
            e.starts_with("line 2:") && e.contains("inside solid"),
            "{e}"
        );
    }

    #[test]
    fn default_path_leads_in_from_a_landmark_digs_and_dips_under_a_slab() {
        use strata_level::generate::{GenerateParams, generate};
        let world = generate(&GenerateParams {
            seed: 7,
            width: 256,
            height: 1024,
        })
        .unwrap();
        let p = default_path(&world);
        let first = &p.keys[0].view;
        assert!(
            world
                .views
                .iter()
                .any(|v| (v.yaw, v.eye, v.pitch) == (first.yaw, first.eye, first.pitch)),
            "starts at a landmark view: {first:?}"
        );
        let dig = p.dig_at.expect("digs");
        assert!(
            dig > 0.4 * p.end() && dig < p.end(),
            "dig at {dig} of {}",
            p.end()
        );
        // Under a slab: the generated depot's roof is over the `under` keys.
        let flight = p.resolve(&world.level).unwrap();
        let under: Vec<&Keyframe> = p.keys.iter().filter(|k| k.view.under).collect();
        assert!(!under.is_empty());
        for k in under {
            let cam = flight.camera(&world.level, k.time, 8, 8).unwrap();
            let c = world.level.column_at(cam.position.x, cam.position.y);
            assert!(c.dual && cam.position.z < f32::from(c.mid), "{k:?} {c:?}");
        }
    }

    #[test]
    fn retiming_scales_keys_and_dig() {
        let p = CameraPath::parse("0,0:0:10 0 2\n0,0:0:10 0 12\ndig 7\n").unwrap();
        let q = p.retimed(5.0);
        assert_eq!((q.start(), q.end(), q.dig_at), (0.0, 5.0, Some(2.5)));
    }
}
