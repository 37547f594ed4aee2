//! The procedural layer under the landmarks: terraced plateaus at a few
//! heights with vertical cliffs, ramp zones, a meandering river valley,
//! roads that climb between levels, and districts of man-made patterns
//! (pit grids, furrowed fields, pillared cave halls, hangar rows).

use super::noise::{Coarse, Fbm, ValueNoise, fast_round, hash2, hash32, unit};
use super::{Slab, Texel};

/// Sea level: the water level every `.vpr` section gets.
pub const SEA: i32 = 80;
/// Plateau heights, lowest (a lake bed, under water) to highest.
pub const LEVELS: [i32; 7] = [62, 92, 112, 132, 156, 180, 208];
/// Band edges on the base noise.
const EDGES: [f32; 6] = [0.30, 0.40, 0.48, 0.56, 0.64, 0.72];
/// Where each band's height sits on the continuous ramp profile.
const RAMP_AT: [f32; 7] = [0.26, 0.35, 0.44, 0.52, 0.60, 0.68, 0.76];

/// Terrain types with fixed roles; the others come from the region map.
pub const WATER: u8 = 0;
pub const ROAD: u8 = 3;
pub const METAL: u8 = 7;

/// Share of slab pairs that crumble away, and of cave ceilings that sag a step.
const EROSION_PERCENT: u32 = 30;
const SAG_PERCENT: u32 = 50;

/// Half width of the roads.
const ROAD_HALF: i32 = 5;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum District {
    Natural,
    Pits,
    Furrows,
    Hall,
    Hangars,
}

/// Everything the per-texel functions need. Built once per world for a
/// world made in memory ([`Terrain::new`]); for a world made chunk by
/// chunk, a cheap [`Terrain::lazy`] is built once and each chunk takes a
/// [`Terrain::window`] of it, which precomputes only what that chunk reads.
/// Every texel is the same bits either way.
#[derive(Clone)]
pub struct Terrain {
    pub seed: u32,
    pub width: u32,
    pub height: u32,
    /// The base noise's two broad octaves, precomputed, and its two fine ones.
    base_broad: Coarse,
    base_fine: Fbm,
    /// Smooth fields sampled together: warp x, warp y, ramp mask, overhang mask, regions.
    fields: Coarse<5>,
    /// Texel-scale wobble of the cliff edges (x and y from one noise).
    jag: ValueNoise,
    fine: ValueNoise,
    river_wobble: ValueNoise,
    river_width: ValueNoise,
    river_phase: [f32; 2],
    river_waves: [f32; 2],
    district_log2: u32,
    /// Per district: its kind, pattern rectangle and flat floor, for the
    /// districts of `district_window` (column, row, columns, rows); others
    /// are planned when asked for.
    districts: Vec<DistrictPlan>,
    district_window: [u32; 4],
    road_period_y: i32,
    road_period_x: i32,
    /// `--floor-roughness`: the small relief's amplitude factor; `None` is
    /// the default world's formula, kept as written so its bytes never move.
    fine_scale: Option<f32>,
}

/// How far past a texel its lookups of the coarse fields reach, texels:
/// the domain warp (32 + 3.5), a road's centre line (5), and the valley
/// overhang's sample at (+91, +45). A window with these margins computes
/// nothing on the spot (the bytes do not depend on it, only the speed).
const REACH_BEFORE: i64 = 48;
const REACH_AFTER_X: i64 = 96;
const REACH_AFTER_Y: i64 = 56;

#[derive(Clone, Copy, Debug)]
struct DistrictPlan {
    kind: District,
    hash: u32,
    /// The pattern's rectangle inside the district: x0, y0, x1, y1 (local).
    rect: [i32; 4],
    floor: i32,
}

/// What is the same along a whole row: the river and the road crossing it.
pub struct Row {
    pub y: u32,
    river: (f32, f32, f32),
    /// Centre row and offset from it, when the row is on an east-west road.
    road: Option<(f32, i32)>,
}

/// Wrapped signed difference `a - b` on a ring of `n`.
#[inline]
pub fn ring_delta(a: f32, b: f32, n: f32) -> f32 {
    let d = (a - b).rem_euclid(n);
    if d > n * 0.5 { d - n } else { d }
}

impl Terrain {
    /// The terrain of a whole map held in memory: every coarse field and
    /// district computed now.
    pub fn new(seed: u64, width: u32, height: u32) -> Self {
        let mut t = Self::lazy(seed, width, height);
        t.base_broad = t.base_broad.window(0, 0, width.into(), height.into());
        t.fields = t.fields.window(0, 0, width.into(), height.into());
        t.plan_districts(0, 0, width, height);
        t
    }

    /// The same terrain with nothing precomputed (a few kilobytes whatever
    /// the map size): for the river, the landmarks' placement and the
    /// views, and as the source of each chunk's [`window`](Self::window).
    pub fn lazy(seed: u64, width: u32, height: u32) -> Self {
        let s = hash32(seed as u32 ^ hash32((seed >> 32) as u32));
        let vn =
            |k: u32, cell: u32| ValueNoise::new(s.wrapping_add(k * 0x9e37), cell, width, height);
        let h = |k: u32| unit(hash32(s ^ k));
        // The river meanders a whole number of times along the map so it wraps.
        let waves = (height / 4096).max(1) as f32;
        let regions = Fbm::new(s ^ 0x7e77, 9, 2, width, height);
        let smooth = [vn(1, 6), vn(2, 6), vn(5, 7), vn(6, 6)];
        let district_log2 = 7
            .min(width.trailing_zeros())
            .min(height.trailing_zeros() - 1);
        Terrain {
            seed: s,
            width,
            height,
            base_broad: {
                let broad = Fbm::octaves(s ^ 0xba5e, 8, 0..2, 4, width, height);
                Coarse::lazy(width, height, 3, move |x, y| [broad.at(x, y)])
            },
            base_fine: Fbm::octaves(s ^ 0xba5e, 8, 2..4, 4, width, height),
            fields: Coarse::lazy(width, height, 3, move |x, y| {
                let [a, b, c, d] = smooth.map(|n| n.at(x, y));
                [a, b, c, d, regions.at(x, y)]
            }),
            jag: vn(3, 3),
            fine: vn(7, 2),
            river_wobble: vn(8, 6),
            river_width: vn(9, 7),
            river_phase: [h(10) * std::f32::consts::TAU, h(11) * std::f32::consts::TAU],
            river_waves: [waves, waves * 3.0],
            district_log2,
            districts: Vec::new(),
            district_window: [0; 4],
            road_period_y: 512.min(height as i32 / 2),
            road_period_x: 1024.min(width as i32),
            fine_scale: None,
        }
    }

    /// This terrain with what the texels `x0 .. x0 + cols`, `y0 .. y0 +
    /// rows` read precomputed: the coarse fields over them and their
    /// margins, and their districts. Texels outside still come out right,
    /// only slower.
    pub fn window(&self, x0: u32, y0: u32, cols: u32, rows: u32) -> Self {
        let (x, y) = (i64::from(x0), i64::from(y0));
        let (x1, y1) = (x + i64::from(cols), y + i64::from(rows));
        let (bx0, by0) = (x - REACH_BEFORE, y - REACH_BEFORE);
        let (bx1, by1) = (x1 + REACH_AFTER_X, y1 + REACH_AFTER_Y);
        let mut t = self.clone();
        t.base_broad = self.base_broad.window(bx0, by0, bx1, by1);
        t.fields = self.fields.window(bx0, by0, bx1, by1);
        t.plan_districts(x0, y0, cols, rows);
        t
    }

    /// Plan the districts holding texels `x0 .. x0 + cols`, `y0 .. y0 + rows`.
    fn plan_districts(&mut self, x0: u32, y0: u32, cols: u32, rows: u32) {
        let l = self.district_log2;
        let (dx0, dy0) = (x0 >> l, y0 >> l);
        let dcols = ((x0 + cols - 1) >> l) - dx0 + 1;
        let drows = ((y0 + rows - 1) >> l) - dy0 + 1;
        self.districts = (dy0..dy0 + drows)
            .flat_map(|dy| (dx0..dx0 + dcols).map(move |dx| (dx, dy)))
            .map(|(dx, dy)| self.plan_district(dx, dy))
            .collect();
        self.district_window = [dx0, dy0, dcols, drows];
    }

    fn plan_district(&self, dx: u32, dy: u32) -> DistrictPlan {
        let size = 1i32 << self.district_log2;
        let hash = hash2(self.seed ^ 0xd15c, dx, dy);
        let kind = match hash % 100 {
            0..=41 => District::Natural,
            42..=55 => District::Pits,
            56..=72 => District::Furrows,
            73..=91 => District::Hall,
            _ => District::Hangars,
        };
        // A pattern covers a random part of its district, not all of it.
        let m = |k: u32| 12 + (hash32(hash ^ k) % (size as u32 / 5)) as i32;
        let rect = [m(1), m(2), size - m(3), size - m(4)];
        let c = |d: u32| (d as i32 * size + size / 2) as f32;
        let floor = LEVELS[Self::band(self.base_noise(c(dx), c(dy))).max(1)];
        DistrictPlan {
            kind,
            hash,
            rect,
            floor,
        }
    }

    /// The plan of district (dx, dy): planned already, or now.
    #[inline]
    fn district_plan(&self, dx: u32, dy: u32) -> DistrictPlan {
        let [wx, wy, wc, wr] = self.district_window;
        let (i, j) = (dx.wrapping_sub(wx), dy.wrapping_sub(wy));
        if i < wc && j < wr {
            self.districts[(j * wc + i) as usize]
        } else {
            self.plan_district(dx, dy)
        }
    }

    /// The per-row context for [`texel`](Self::texel).
    pub fn row(&self, y: u32) -> Row {
        let period_y = self.road_period_y;
        let ry = (y as i32).rem_euclid(period_y) - period_y / 2;
        Row {
            y,
            river: self.river(y as f32),
            road: (ry.abs() <= ROAD_HALF).then_some((y as f32 - ry as f32, ry)),
        }
    }

    /// Scale the small relief (bumps and specks) by `scale` (1: as the
    /// default world; see [`super::Knobs::floor_roughness`]).
    pub fn set_fine_scale(&mut self, scale: f32) {
        self.fine_scale = Some(scale);
    }

    /// Small organic bumps for flat ground: a few units, blob-shaped.
    #[inline]
    pub fn fine(&self, x: f32, y: f32) -> i32 {
        let v = self.fine.at(x, y);
        let mixed = (x as u32).wrapping_mul(0x9e37_79b1) ^ (y as u32).wrapping_mul(0x85eb_ca77);
        let speck = (hash32(mixed ^ self.seed) & 15 == 0) as i32;
        match self.fine_scale {
            None => fast_round((v - 0.5) * 5.0) + speck,
            Some(s) => fast_round((v - 0.5) * 5.0 * s) + fast_round(speck as f32 * s),
        }
    }

    /// Terrain type of the region around (x, y): 1..=7 in broad patches.
    #[inline]
    pub fn region_type(&self, x: f32, y: f32) -> u8 {
        Self::type_of(self.fields.all(x, y)[4])
    }

    #[inline]
    fn type_of(region: f32) -> u8 {
        (((region - 0.25) * 14.0).clamp(0.0, 6.0) as u8) + 1
    }

    #[inline]
    fn base_noise(&self, x: f32, y: f32) -> f32 {
        self.base_noise_with(x, y, &self.fields.all(x, y))
    }

    #[inline]
    fn base_noise_with(&self, x: f32, y: f32, f: &[f32; 5]) -> f32 {
        let (jx, jy) = self.jag.at2(x, y);
        let wx = x + (f[0] - 0.5) * 64.0 + (jx - 0.5) * 7.0;
        let wy = y + (f[1] - 0.5) * 64.0 + (jy - 0.5) * 7.0;
        self.base_broad.at(wx, wy) + self.base_fine.at(wx, wy)
    }

    /// Height on the continuous profile through the band heights (ramps, roads).
    pub fn ramp_height(n: f32) -> f32 {
        if n <= RAMP_AT[0] {
            return LEVELS[0] as f32;
        }
        for i in 1..RAMP_AT.len() {
            if n <= RAMP_AT[i] {
                let t = (n - RAMP_AT[i - 1]) / (RAMP_AT[i] - RAMP_AT[i - 1]);
                return LEVELS[i - 1] as f32 + t * (LEVELS[i] - LEVELS[i - 1]) as f32;
            }
        }
        LEVELS[6] as f32
    }

    #[inline]
    fn band(n: f32) -> usize {
        EDGES.iter().take_while(|&&e| n >= e).count()
    }

    /// Centre of the river at row y, and its half widths (water, valley).
    pub fn river(&self, y: f32) -> (f32, f32, f32) {
        let (w, h) = (self.width as f32, self.height as f32);
        let t = y / h * std::f32::consts::TAU;
        let x = w * 0.5
            + w * 0.2 * (t * self.river_waves[0] + self.river_phase[0]).sin()
            + w * 0.05 * (t * self.river_waves[1] + self.river_phase[1]).sin()
            + (self.river_wobble.at(0.0, y) - 0.5) * 40.0;
        let rw = 9.0 + 12.0 * self.river_width.at(0.0, y);
        // Narrow maps get a narrower valley, so the river does not take them over.
        let scale = (w / 2048.0).clamp(0.4, 1.0);
        let vw = rw + (14.0 + 22.0 * self.river_width.at(64.0, y)) * scale;
        (x, rw, vw)
    }

    /// The plateau layer alone: floor, band, type, and an overhanging slab
    /// where a higher plateau reaches out over this texel.
    fn plateau(&self, xf: f32, yf: f32) -> (Texel, usize) {
        let f = self.fields.all(xf, yf);
        let n = self.base_noise_with(xf, yf, &f);
        let band = Self::band(n);
        let ramp = f[2] > 0.74;
        let ty = Self::type_of(f[4]);
        let mut floor = if ramp {
            fast_round(Self::ramp_height(n))
        } else {
            LEVELS[band]
        };
        floor += self.fine(xf, yf);
        let mut t = Texel::single(floor, if floor < SEA { WATER } else { ty });
        // Overhangs: the higher band "reaches" this texel if nudging the noise
        // by `reach` crosses an edge; the nudge varies so edges overhang in stretches.
        let reach = (f[3] - 0.45).max(0.0) * 0.12;
        if !ramp && reach > 0.0 && band < EDGES.len() {
            let up = Self::band(n + reach);
            if up > band {
                let high = LEVELS[up] + self.fine(xf + 17.0, yf);
                let thick = 6 + (hash2(self.seed, xf as u32 >> 4, yf as u32 >> 4) % 8) as i32;
                t.slab = Some(Slab {
                    ceiling: high - thick,
                    high,
                    ty,
                });
            }
        }
        (t, band)
    }

    /// The procedural texel at (x, y), landmarks aside.
    pub fn texel(&self, x: u32, row: &Row) -> Texel {
        let mut t = self.texel_whole(x, row);
        // Water is exactly the ground below sea level.
        if (t.ty == WATER) != (t.floor < SEA) {
            t.ty = if t.floor < SEA {
                WATER
            } else {
                self.region_type(x as f32, row.y as f32)
            };
        }
        match t.slab {
            Some(s) => self.weather(t, s, x >> 1, row.y),
            None => t,
        }
    }

    /// Slabs are not machined: some pairs crumble away (ragged holes and
    /// edges), cave ceilings sag by a gap step here and there, and roofs
    /// carry rubble. Per pair, so both texels of a pair agree.
    fn weather(&self, t: Texel, s: Slab, pair: u32, y: u32) -> Texel {
        let h = hash2(self.seed ^ 0xc7, pair, y);
        if h % 100 < EROSION_PERCENT {
            return Texel { slab: None, ..t };
        }
        let sag = if (h >> 8) % 100 < SAG_PERCENT { 8 } else { 0 };
        let rubble = ((h >> 16) % 8) as i32;
        Texel {
            slab: Some(Slab {
                ceiling: s.ceiling - sag,
                high: s.high + rubble,
                ..s
            }),
            ..t
        }
    }

    fn texel_whole(&self, x: u32, row: &Row) -> Texel {
        let y = row.y;
        let (xf, yf) = (x as f32, y as f32);
        let (mut t, band) = self.plateau(xf, yf);

        // River valley: water channel inside flat valley floor, cut into the plateaus.
        let (rx, rw, vw) = row.river;
        let dx = ring_delta(xf, rx, self.width as f32).abs();
        let in_valley = dx < vw;
        if in_valley {
            let wall = t.floor;
            let valley = if dx < rw { 64 } else { 90 };
            if wall > valley || dx < rw {
                t = Texel::single(
                    valley + self.fine(xf, yf),
                    if dx < rw {
                        WATER
                    } else {
                        self.region_type(xf, yf)
                    },
                );
                // The plateau above overhangs the valley wall in stretches.
                let reach = (self.fields.all(xf + 91.0, yf + 45.0)[3] - 0.45).max(0.0) * 40.0;
                if dx > vw - reach && wall >= valley + 20 {
                    t.slab = Some(Slab {
                        ceiling: wall - 8,
                        high: wall,
                        ty: self.region_type(xf, yf),
                    });
                }
            }
        }

        // Roads: flat across, following the smooth profile along, so they climb
        // between terraces in cuttings and on causeways, and bridge the river.
        let period_x = self.road_period_x;
        let rxo = (x as i32 + period_x / 4).rem_euclid(period_x) - period_x / 2;
        if let Some((cy, ry)) = row.road {
            let n = self.base_noise(xf, cy);
            let hr = (fast_round(Self::ramp_height(n))).max(96);
            return self.road_texel(t, hr, in_valley, xf, yf, ry);
        }
        if rxo.abs() <= ROAD_HALF && !in_valley {
            let n = self.base_noise(xf - rxo as f32, yf);
            let hr = (fast_round(Self::ramp_height(n))).max(96);
            return self.road_texel(t, hr, in_valley, xf, yf, rxo);
        }
        if in_valley || band == 0 {
            return t;
        }
        self.district(t, x, y)
    }

    fn road_texel(
        &self,
        under: Texel,
        hr: i32,
        in_valley: bool,
        xf: f32,
        yf: f32,
        across: i32,
    ) -> Texel {
        // Kerbs: the two edge texels stand a little higher.
        let kerb = if across.abs() == ROAD_HALF { 2 } else { 0 };
        if in_valley && under.floor < hr - 12 {
            // A bridge deck over the valley, water or floor below it.
            return Texel {
                slab: Some(Slab {
                    ceiling: hr - 6,
                    high: hr + kerb,
                    ty: ROAD,
                }),
                ..under
            };
        }
        let _ = (xf, yf);
        Texel::single(hr + kerb, ROAD)
    }

    /// Man-made patterns laid over the plateau inside a district's rectangle.
    fn district(&self, t: Texel, x: u32, y: u32) -> Texel {
        let size = 1i32 << self.district_log2;
        let (dx, dy) = (x >> self.district_log2, y >> self.district_log2);
        let plan = self.district_plan(dx, dy);
        let (lx, ly) = ((x as i32) & (size - 1), (y as i32) & (size - 1));
        let [x0, y0, x1, y1] = plan.rect;
        if lx < x0 || ly < y0 || lx >= x1 || ly >= y1 {
            return t;
        }
        let lot = Lot {
            floor: plan.floor,
            lx: lx - x0,
            ly: ly - y0,
            pw: x1 - x0,
            ph: y1 - y0,
            h: plan.hash,
            xf: x as f32,
            yf: y as f32,
        };
        match plan.kind {
            District::Natural => t,
            District::Pits => pits(self, t, &lot),
            District::Furrows => furrows(t, &lot),
            District::Hall => hall(self, &lot),
            District::Hangars => hangars(self, &lot),
        }
    }
}

/// Where in its district's rectangle a texel lies, and what the patterns
/// read of the district.
struct Lot {
    /// The district's floor height.
    floor: i32,
    /// The texel in the rectangle.
    lx: i32,
    ly: i32,
    /// The rectangle's size.
    pw: i32,
    ph: i32,
    /// The district's hash.
    h: u32,
    /// The texel in the map, for the noise.
    xf: f32,
    yf: f32,
}

/// A grid of round pits, each stepped with a raised rim.
fn pits(tr: &Terrain, t: Texel, lot: &Lot) -> Texel {
    let &Lot {
        lx, ly, h, xf, yf, ..
    } = lot;
    let sp = 20 + 4 * (h % 3) as i32;
    let r = sp as f32 * 0.33;
    let u = (lx % sp) as f32 - sp as f32 * 0.5 + 0.5;
    let v = (ly % sp) as f32 - sp as f32 * 0.5 + 0.5;
    let d = (u * u + v * v).sqrt();
    let base = t.floor - tr.fine(xf, yf);
    let pit_ty = (t.ty % 7) + 1;
    if t.slab.is_some() {
        return t;
    }
    if d < r * 0.62 {
        Texel::single((base - 34).max(SEA + 4), pit_ty)
    } else if d < r {
        Texel::single((base - 14).max(SEA + 6), pit_ty)
    } else if d < r + 1.6 {
        Texel::single(base + 3, t.ty)
    } else {
        t
    }
}

/// Fields of parallel ridges, four patches with their own direction.
fn furrows(t: Texel, lot: &Lot) -> Texel {
    let &Lot {
        lx, ly, pw, ph, h, ..
    } = lot;
    if t.slab.is_some() {
        return t;
    }
    let (hw, hh) = (pw / 2, ph / 2);
    let quadrant = ((lx >= hw) as u32) | (((ly >= hh) as u32) << 1);
    let (qx, qy) = (lx % hw.max(1), ly % hh.max(1));
    if qx < 3 || qy < 3 || qx >= hw - 3 || qy >= hh - 3 {
        return t; // paths between the fields
    }
    let hq = hash32(h ^ quadrant);
    let period = 6 + (hq % 3) as i32;
    let along = match hq % 3 {
        0 => qx,
        1 => qy,
        _ => qx + qy,
    };
    let ty = 2 + (hq % 2) as u8 * 4; // brown or dark-green farmland
    let ridge = (along % period < period / 2) as i32 * 5;
    Texel::single(t.floor + ridge, ty)
}

/// A pillared cave hall: a flat roof slab over a flat floor, walls with
/// doorways, square pillars and a few skylights.
fn hall(tr: &Terrain, lot: &Lot) -> Texel {
    let &Lot {
        floor,
        lx,
        ly,
        pw,
        ph,
        h,
        xf,
        yf,
    } = lot;
    let ty = tr.region_type(xf, yf);
    let roof_ty = (ty + 2) % 7 + 1;
    let top = floor + 34 + (h % 3) as i32 * 8;
    let ground = floor + tr.fine(xf, yf);
    let edge = lx.min(ly).min(pw - 1 - lx).min(ph - 1 - ly);
    let door = (lx - pw / 2).abs().min((ly - ph / 2).abs()) < 8;
    if edge < 3 {
        return if door {
            Texel::single(ground, ty)
        } else {
            Texel::single(top, roof_ty)
        };
    }
    let pitch = 32;
    let (px, py) = (lx % pitch, ly % pitch);
    if px < 4 && py < 4 {
        return Texel::single(top, roof_ty); // pillar
    }
    let (cx, cy) = ((lx / pitch) as u32, (ly / pitch) as u32);
    if hash2(h, cx, cy).is_multiple_of(5) && (10..26).contains(&px) && (10..26).contains(&py) {
        return Texel::single(ground, ty); // skylight
    }
    Texel {
        floor: ground,
        ty,
        slab: Some(Slab {
            ceiling: floor + 24,
            high: top + tr.fine(xf + 5.0, yf),
            ty: roof_ty,
        }),
    }
}

/// A row of arch-roofed hangars on a flat apron, open at the south end.
fn hangars(tr: &Terrain, lot: &Lot) -> Texel {
    let ground = lot.floor + (tr.fine(lot.xf, lot.yf) >> 1);
    // Apron markings: a raised line every 16 texels.
    let apron = Texel::single(
        ground + ((lot.lx % 16 == 0 || lot.ly % 16 == 0) as i32),
        ROAD,
    );
    let (hw, gap) = (40, 16);
    let hl = (72 + (lot.h % 3) as i32 * 16).min(lot.ph - 8);
    let stride = hw + gap;
    let count = (lot.pw - gap) / stride;
    let k = (lot.lx - gap / 2) / stride;
    let u = (lot.lx - gap / 2) % stride;
    let v = lot.ly - (lot.ph - hl) / 2;
    if k >= count || lot.lx < gap / 2 || u >= hw || v < 0 || v >= hl {
        return apron;
    }
    let tt = (u as f32 + 0.5 - hw as f32 * 0.5) / (hw as f32 * 0.5);
    let roof = lot.floor + 22 + (14.0 * (1.0 - tt * tt).max(0.0).sqrt()).round() as i32;
    if u < 2 || u >= hw - 2 || v >= hl - 2 {
        return Texel::single(roof, METAL); // side and back walls
    }
    // A low lintel over the open front, the full hall height inside.
    apron.with_slab(lot.floor + if v < 4 { 16 } else { 20 }, roof, METAL)
}
