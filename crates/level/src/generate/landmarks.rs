//! Named landmarks: hand-designed sites stamped over the procedural terrain,
//! placed relative to the map size, with the default views and the edit site
//! over them. Designs are in local coordinates scaled by the site size `c`
//! (128 texels on large maps, 64 on small ones); heights do not scale.

use super::terrain::{LEVELS, METAL, ROAD, Terrain, WATER, ring_delta};
use super::{GenerateError, Texel};
use crate::views::{EditSite, ViewSpec};

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kind {
    Bridge,
    Hangar,
    Ramp,
    Portal,
    Pits,
    Fields,
    Canyon,
    Spiral,
    Lake,
    Depot,
}

impl Kind {
    pub fn name(self) -> &'static str {
        match self {
            Kind::Bridge => "bridge",
            Kind::Hangar => "hangar",
            Kind::Ramp => "ramp",
            Kind::Portal => "portal",
            Kind::Pits => "pits",
            Kind::Fields => "fields",
            Kind::Canyon => "canyon",
            Kind::Spiral => "spiral",
            Kind::Lake => "lake",
            Kind::Depot => "depot",
        }
    }

    pub fn describe(self) -> &'static str {
        match self {
            Kind::Bridge => "a slab bridge over the river between sheer banks",
            Kind::Hangar => "an arch-roofed hangar with a low lintel over its open front",
            Kind::Ramp => "a ribbed causeway ramp up a 44-unit cliff",
            Kind::Portal => "a road in a trench passing under an arch",
            Kind::Pits => "a grid of stepped round pits, the middle one bridged",
            Kind::Fields => "four furrowed fields in different directions",
            Kind::Canyon => "a deep canyon with overhanging rims and a span",
            Kind::Spiral => "a spiral ramp winding down from a summit",
            Kind::Lake => "a round lake with an island and a pier",
            Kind::Depot => "the edit site: a roofed depot the crater cuts into",
        }
    }
}

/// A placed landmark: its footprint on the map and its design scale.
#[derive(Clone, Debug)]
pub struct Landmark {
    pub kind: Kind,
    pub x0: u32,
    pub y0: u32,
    pub w: u32,
    pub h: u32,
    /// Design scale: the side of a one-cell site.
    pub c: i32,
}

impl Landmark {
    #[inline]
    pub fn covers_row(&self, y: u32) -> bool {
        y >= self.y0 && y < self.y0 + self.h
    }

    #[inline]
    pub fn covers_x(&self, x: u32) -> bool {
        x >= self.x0 && x < self.x0 + self.w
    }

    fn overlaps(&self, x0: u32, y0: u32, w: u32, h: u32) -> bool {
        self.x0 < x0 + w && x0 < self.x0 + self.w && self.y0 < y0 + h && y0 < self.y0 + self.h
    }

    /// World position of local coordinates (fractions of `c`).
    fn at(&self, u: f32, v: f32) -> (f32, f32) {
        (
            self.x0 as f32 + u * self.c as f32,
            self.y0 as f32 + v * self.c as f32,
        )
    }

    fn scale(&self) -> f32 {
        self.c as f32 / 128.0
    }

    /// The designed texel at map position (x, y) inside the footprint.
    pub fn texel(&self, t: &Terrain, x: u32, y: u32) -> Texel {
        let (u, v) = ((x - self.x0) as i32, (y - self.y0) as i32);
        let (xf, yf) = (x as f32, y as f32);
        let c = self.c;
        let cf = c as f32;
        let fine = t.fine(xf, yf);
        let ty = t.region_type(xf, yf);
        match self.kind {
            Kind::Bridge => {
                let (cx, half) = self.channel(t, yf);
                let d = (u as f32 + 0.5 - cx).abs();
                let deck = (v - c / 2).abs() <= 2 + c / 16;
                let floor = if d < half {
                    Texel::single(64 + fine, WATER)
                } else {
                    Texel::single(LEVELS[2] + fine, ty)
                };
                if deck && d < half + 3.0 {
                    let rail = ((v - c / 2).abs() == 2 + c / 16) as i32 * 3;
                    return floor.with_slab(LEVELS[2] - 6, LEVELS[2] + 1 + rail, ROAD);
                }
                if deck {
                    return Texel::single(LEVELS[2] + 1, ROAD);
                }
                floor
            }
            Kind::Hangar => {
                let b = LEVELS[2];
                let apron =
                    Texel::single(b + (fine >> 1) + (u % 16 == 0 || v % 16 == 0) as i32, ROAD);
                let (u0, u1, v0, v1) = (c / 4, 3 * c / 4, 9 * c / 20, 19 * c / 20);
                if u < u0 || u >= u1 || v < v0 || v >= v1 {
                    return apron;
                }
                let tt = (u as f32 + 0.5 - cf * 0.5) / (cf * 0.25);
                let roof = b + 30 + (10.0 * (1.0 - tt * tt).max(0.0).sqrt()).round() as i32;
                if u < u0 + 3 || u >= u1 - 3 || v >= v1 - 3 {
                    return Texel::single(roof, METAL);
                }
                let ceiling = b + if v < v0 + 4 { 16 } else { 24 };
                apron.with_slab(ceiling, roof, METAL)
            }
            Kind::Ramp => {
                let (lo, hi) = (100, 144);
                let (r0, r1) = (3 * c / 10, 13 * c / 20);
                let on_road = (u - c / 2).abs() < c / 10;
                if on_road && v >= r0 && v < r1 {
                    let h = lo + (hi - lo) * (v - r0) / (r1 - r0);
                    let rail = ((u - c / 2).abs() == c / 10 - 1) as i32 * 3;
                    return Texel::single(h + (v % 3 == 0) as i32 + rail, ROAD);
                }
                if on_road && v >= r1 {
                    return Texel::single(hi, ROAD);
                }
                Texel::single(if v >= r1 { hi } else { lo } + fine, ty)
            }
            Kind::Portal => {
                let (lo, hi) = (100, 150);
                let trench = (u - c / 2).abs() < 3 * c / 25;
                if !trench {
                    return Texel::single(hi + fine, ty);
                }
                let floor = Texel::single(lo + (fine >> 1), ROAD);
                if v >= c / 2 && v < 5 * c / 8 {
                    return floor.with_slab(lo + 26, hi + fine, METAL);
                }
                floor
            }
            Kind::Pits => {
                let b = 120;
                let sp = 24;
                let (cu, cv) = (u % sp, v % sp);
                let (du, dv) = (cu as f32 - 11.5, cv as f32 - 11.5);
                let d = (du * du + dv * dv).sqrt();
                let pit_ty = ty % 7 + 1;
                let middle = u / sp == (c / 2) / sp && v / sp == (c / 2) / sp;
                let ground = if d < 5.0 {
                    Texel::single(b - 36, pit_ty)
                } else if d < 8.5 {
                    Texel::single(b - 14, pit_ty)
                } else if d < 10.0 {
                    Texel::single(b + 3, ty)
                } else {
                    Texel::single(b + fine, ty)
                };
                if middle && (du.abs() < 3.0 || dv.abs() < 3.0) && d < 10.0 {
                    return ground.with_slab(b - 8, b + 1, METAL);
                }
                ground
            }
            Kind::Fields => {
                let b = 104;
                let half = c / 2;
                let (qu, qv) = (u % half, v % half);
                if qu < 3 || qv < 3 || qu >= half - 3 || qv >= half - 3 {
                    return Texel::single(b + 1, ROAD);
                }
                let q = (u / half + 2 * (v / half)) as u32;
                let period = 6 + (q % 3) as i32;
                let along = match q {
                    0 => qu,
                    1 => qv,
                    2 => qu + qv,
                    _ => qu + half - qv,
                };
                let ridge = (along % period < period / 2) as i32 * 5;
                Texel::single(b + ridge, 2 + (q % 2) as u8 * 4)
            }
            Kind::Canyon => {
                let top = 170;
                let d = (u as f32 + 0.5 - cf * 0.5).abs();
                let half = 0.16 * cf;
                let over = 5.0 + 4.0 * (v as f32 * 0.15).sin();
                let span = v >= 7 * c / 10 && v < 7 * c / 10 + 6;
                if d >= half {
                    return Texel::single(top + fine, ty);
                }
                let floor = Texel::single(84 + fine, (ty + 3) % 7 + 1);
                if span {
                    return floor.with_slab(top - 8, top + 2, METAL);
                }
                if d >= half - over {
                    return floor.with_slab(top - 12, top + fine, ty);
                }
                floor
            }
            Kind::Spiral => {
                let (du, dv) = (u as f32 + 0.5 - cf * 0.5, v as f32 + 0.5 - cf * 0.5);
                let r = (du * du + dv * dv).sqrt();
                let pitch = 12.0 * self.scale().max(0.75);
                let r_max = 0.46 * cf;
                if r >= r_max {
                    return Texel::single(104 + fine, ty);
                }
                let alpha = (du.atan2(dv) / std::f32::consts::TAU).rem_euclid(1.0);
                let rho = (r - 3.0) / pitch;
                let k = (rho - alpha).floor();
                let frac = rho - alpha - k;
                let q = (k + alpha).max(0.0);
                let road = 206 - (20.0 * q).round() as i32;
                if frac < 0.6 || r < 5.0 {
                    Texel::single(road.max(110), ROAD)
                } else {
                    Texel::single((road - 22).max(96), ty)
                }
            }
            Kind::Lake => {
                let (du, dv) = (u as f32 + 0.5 - cf * 0.5, v as f32 + 0.5 - cf * 0.5);
                let r = (du * du + dv * dv).sqrt();
                let (lake, island) = (0.42 * cf, 0.13 * cf);
                if r >= lake {
                    return Texel::single(104 + fine, ty);
                }
                if r < island {
                    return Texel::single(120 + fine, (ty + 4) % 7 + 1);
                }
                let water = Texel::single(62 + fine, WATER);
                if du.abs() < 3.0 && dv > 0.0 {
                    return water.with_slab(88, 96, ROAD);
                }
                water
            }
            Kind::Depot => {
                let b = LEVELS[2];
                let (cx, cy) = self.crater_local();
                let ground = Texel::single(b + (fine >> 1) + (u % 16 == 0) as i32, ROAD);
                // The roofed depot straddles the crater's north half.
                let (u0, u1) = (cx - 40, cx + 40);
                let (v0, v1) = (cy - 48, cy - 4);
                if u < u0 || u >= u1 || v < v0 || v >= v1 {
                    return ground;
                }
                if u < u0 + 3 || u >= u1 - 3 || v < v0 + 3 {
                    return Texel::single(b + 40, METAL);
                }
                ground.with_slab(b + 24, b + 40 + (fine >> 1), METAL)
            }
        }
    }

    /// The bridge site's straightened river: channel centre (local x) and half width at row y.
    fn channel(&self, t: &Terrain, y: f32) -> (f32, f32) {
        let w = t.width as f32;
        let local = |yy: f32| ring_delta(t.river(yy).0, self.x0 as f32, w);
        let (a, b) = (local(self.y0 as f32), local((self.y0 + self.h) as f32));
        let s = (y - self.y0 as f32) / self.h as f32;
        let cf = self.c as f32;
        ((a + (b - a) * s).clamp(0.3 * cf, 0.7 * cf), 0.14 * cf)
    }

    /// Crater centre of the depot in local coordinates.
    fn crater_local(&self) -> (i32, i32) {
        (self.w as i32 / 2, 56.min(self.c / 2))
    }
}

/// The placed sites.
pub struct Layout {
    pub list: Vec<Landmark>,
}

const ORDER: [Kind; 10] = [
    Kind::Bridge,
    Kind::Depot,
    Kind::Hangar,
    Kind::Ramp,
    Kind::Portal,
    Kind::Pits,
    Kind::Fields,
    Kind::Canyon,
    Kind::Spiral,
    Kind::Lake,
];

/// Place the landmarks: spread along the map's length, away from the river
/// where there is room, never overlapping each other.
pub fn place(t: &Terrain) -> Result<Layout, GenerateError> {
    let (w, h) = (t.width, t.height);
    let c: u32 = if w >= 512 && h >= 1024 { 128 } else { 64 };
    let (cols, rows) = (w / c, h / c);
    let mut list: Vec<Landmark> = Vec::new();
    let n = ORDER.len() as u32;
    for (i, &kind) in ORDER.iter().enumerate() {
        let (bw, bh) = match kind {
            Kind::Depot if c == 128 => (1, 2),
            Kind::Depot => (2, 3),
            _ => (1, 1),
        };
        let target = ((2 * i as u32 + 1) * rows / (2 * n)).min(rows - 1);
        let mut placed = None;
        'search: for step in 0..rows {
            for row in [target as i64 + step as i64, target as i64 - step as i64] {
                if row < 0 || row as u32 + bh > rows || (step == 0 && row != target as i64) {
                    continue;
                }
                let row = row as u32;
                let y0 = row * c;
                let yc = (y0 + bh * c / 2) as f32;
                let river = t.river(yc).0;
                if kind == Kind::Bridge {
                    let x0 = (river - c as f32 / 2.0).rem_euclid(w as f32) as u32;
                    let x0 = x0.min(w - c);
                    if !list.iter().any(|l| l.overlaps(x0, y0, c, c)) {
                        placed = Some((x0, y0));
                        break 'search;
                    }
                    continue;
                }
                // Columns farthest from the river first.
                let mut candidates: Vec<u32> = (0..=cols - bw).collect();
                let dist = |col: u32| {
                    let xc = ((col * c) + bw * c / 2) as f32;
                    ring_delta(xc, river, w as f32).abs()
                };
                candidates.sort_by(|&a, &b| dist(b).total_cmp(&dist(a)).then(a.cmp(&b)));
                for col in candidates {
                    let x0 = col * c;
                    if !list.iter().any(|l| l.overlaps(x0, y0, bw * c, bh * c)) {
                        placed = Some((x0, y0));
                        break 'search;
                    }
                }
            }
        }
        let (x0, y0) = placed.ok_or(GenerateError::NoRoom {
            width: w,
            height: h,
            landmark: kind.name(),
        })?;
        list.push(Landmark {
            kind,
            x0,
            y0,
            w: bw * c,
            h: bh * c,
            c: c as i32,
        });
    }
    Ok(Layout { list })
}

/// Yaw (degrees) that looks from (x, y) towards (tx, ty): yaw 0 is +y, 90 is +x.
fn yaw_to(from: (f32, f32), to: (f32, f32)) -> f32 {
    let yaw = (to.0 - from.0).atan2(to.1 - from.1).to_degrees();
    (yaw.rem_euclid(360.0) * 10.0).round() / 10.0
}

fn view(name: &str, at: (f32, f32), yaw: f32, eye: f32, pitch: f32) -> ViewSpec {
    ViewSpec {
        name: name.into(),
        x: at.0.round(),
        y: at.1.round(),
        yaw,
        eye,
        under: false,
        pitch,
    }
}

/// A camera `eye` above the ground that looks at `target` along `yaw` at a
/// downward `pitch`: it stands back by `eye / tan(pitch)`.
fn aimed(name: &str, target: (f32, f32), yaw: f32, eye: f32, pitch: f32) -> ViewSpec {
    let back = if pitch <= -89.0 {
        0.0
    } else {
        eye / (-pitch).to_radians().tan()
    };
    let (s, c) = yaw.to_radians().sin_cos();
    view(
        name,
        (target.0 - s * back, target.1 - c * back),
        yaw,
        eye,
        pitch,
    )
}

impl Layout {
    fn get(&self, kind: Kind) -> &Landmark {
        self.list
            .iter()
            .find(|l| l.kind == kind)
            .expect("place() puts every kind")
    }

    /// The twelve default views, three per pitch 0, -30, -60, -90.
    pub fn views(&self, t: &Terrain) -> Vec<ViewSpec> {
        let bridge = self.get(Kind::Bridge);
        let cf = bridge.c as f32;
        let on_channel = |v: f32| {
            let y = bridge.y0 as f32 + v * cf;
            (bridge.x0 as f32 + bridge.channel(t, y).0, y)
        };
        let (river_eye, deck) = (on_channel(0.93), on_channel(0.5));
        let hangar = self.get(Kind::Hangar);
        let s = hangar.scale();
        let ramp = self.get(Kind::Ramp);
        let portal = self.get(Kind::Portal);
        let bank = (deck.0 + 0.34 * cf, bridge.y0 as f32 + 0.97 * cf);
        let lift = |eye: f32, l: &Landmark| eye * (0.5 + 0.5 * l.scale());
        vec![
            view("river", river_eye, yaw_to(river_eye, deck), 30.0, 0.0),
            view("hangar", hangar.at(0.5, 0.1), 0.0, 22.0, 0.0),
            view("ramp", ramp.at(0.5, 0.04), 0.0, 14.0, 0.0),
            view("portal", portal.at(0.5, 0.04), 0.0, 34.0 + 26.0 * s, -30.0),
            aimed(
                "entrance",
                hangar.at(0.5, 0.47),
                340.0,
                lift(46.0, hangar),
                -30.0,
            ),
            view("river-down", bank, yaw_to(bank, deck), 40.0, -30.0),
            aimed(
                "pits",
                self.get(Kind::Pits).at(0.5, 0.5),
                200.0,
                lift(110.0, hangar),
                -60.0,
            ),
            aimed(
                "fields",
                self.get(Kind::Fields).at(0.5, 0.5),
                135.0,
                lift(120.0, hangar),
                -60.0,
            ),
            aimed(
                "canyon",
                self.get(Kind::Canyon).at(0.5, 0.55),
                10.0,
                lift(90.0, hangar),
                -60.0,
            ),
            view(
                "spiral",
                self.get(Kind::Spiral).at(0.5, 0.5),
                10.0,
                lift(150.0, hangar),
                -90.0,
            ),
            view(
                "lake",
                self.get(Kind::Lake).at(0.5, 0.5),
                0.0,
                lift(200.0, hangar),
                -90.0,
            ),
            {
                let d = self.get(Kind::Depot);
                let (cx, cy) = d.crater_local();
                view(
                    "depot",
                    (d.x0 as f32 + cx as f32, d.y0 as f32 + cy as f32),
                    0.0,
                    lift(180.0, d),
                    -90.0,
                )
            },
        ]
    }

    /// The crater and its camera: like the paper's, looking north at the
    /// crater from 158 units south (less on small maps) at pitch -30, but
    /// with the eye 90 up instead of 40: that puts the crater on the view
    /// axis, so it is in the picture at every image size (at eye 40 its
    /// centre is 16 degrees above the axis, outside a 200-pixel-tall image).
    pub fn edit_site(&self) -> EditSite {
        let d = self.get(Kind::Depot);
        let (cx, cy) = d.crater_local();
        let (cx, cy) = (d.x0 as i64 + cx as i64, d.y0 as i64 + cy as i64);
        let back = 158.min(d.h as i64 - (cy - d.y0 as i64) - 8);
        EditSite {
            centre_x: cx,
            centre_y: cy,
            radius: 48,
            depth: 90.0,
            camera: ViewSpec {
                name: "edit".into(),
                x: cx as f32,
                y: (cy + back) as f32,
                yaw: 180.0,
                eye: 90.0,
                under: false,
                pitch: -30.0,
            },
        }
    }
}
