//! The region's triangles as an indexed, coloured triangle list.

use crate::color::type_colors;
use crate::error::ExportError;
use crate::region::Region;
use rayon::prelude::*;
use std::collections::HashMap;
use strata_level::World;
use strata_mesh::{ChunkFitter, ChunkLayout, ChunkMesh, decode, tolerance_for_quality};

/// The fitted mesh (finest LOD) of a region, ready to write: whole
/// triangles whose centroid lies in the region, vertices shared within a
/// chunk, in the terrain frame (x, y texels, z up; unwrapped).
pub struct TerrainSoup {
    /// Vertex positions.
    pub positions: Vec<[f32; 3]>,
    /// Vertex colours (RGBA8), the terrain type's colour.
    pub colors: Vec<[u8; 4]>,
    /// Triangles, counter-clockwise seen from outside the solid.
    pub triangles: Vec<[u32; 3]>,
    /// The mesh's max vertical error (the fit tolerance).
    pub max_error: f64,
}

impl TerrainSoup {
    /// Fit the chunks under `region` at quality `q` and collect their
    /// triangles.
    pub fn build(world: &World, region: Region, q: f64) -> Result<Self, ExportError> {
        let tol = tolerance_for_quality(q).ok_or(ExportError::Quality(q))?;
        let level = &world.level;
        let layout = ChunkLayout::of(level);
        let (sx, sy) = (i64::from(layout.size_x), i64::from(layout.size_y));
        // Chunk squares start at texel centres (+0.5): cell g covers
        // [g*size + 0.5, (g+1)*size + 0.5].
        let cells = |lo: i64, hi: i64, s: i64| {
            let first = (lo as f64 - 0.5).div_euclid(s as f64) as i64;
            let last = (hi as f64 - 0.5).div_euclid(s as f64) as i64;
            first..=last
        };
        let cell_list: Vec<(i64, i64)> = cells(region.y0, region.y1, sy)
            .flat_map(|gy| cells(region.x0, region.x1, sx).map(move |gx| (gx, gy)))
            .collect();
        let chunk_of = |gx: i64, gy: i64| {
            layout.index(
                gx.rem_euclid(i64::from(layout.chunks_x)) as u32,
                gy.rem_euclid(i64::from(layout.chunks_y)) as u32,
            )
        };
        let mut ids: Vec<usize> = cell_list.iter().map(|&(x, y)| chunk_of(x, y)).collect();
        ids.sort_unstable();
        ids.dedup();
        let meshes: HashMap<usize, ChunkMesh> = ids
            .par_iter()
            .map_init(ChunkFitter::default, |f, &i| {
                let (cx, cy) = layout.coords(i);
                (i, f.fit(level, &layout, cx, cy, tol))
            })
            .collect();
        let colors = type_colors(world);
        let mut soup = TerrainSoup {
            positions: Vec::new(),
            colors: Vec::new(),
            triangles: Vec::new(),
            max_error: tol,
        };
        let stride = layout.size_x + 1;
        let positions = stride * (layout.size_y + 1);
        let mut slot = vec![u32::MAX; (positions * 3) as usize];
        for &(gx, gy) in &cell_list {
            let mesh = &meshes[&chunk_of(gx, gy)];
            let (ox, oy) = (gx * sx, gy * sy);
            slot.fill(u32::MAX);
            for tri in mesh.lod_triangles(0) {
                let vs = tri.map(|i| decode(i, stride, positions));
                let centre = vs.iter().fold((0.0, 0.0), |(a, b), &(x, y, _)| {
                    (a + f64::from(x) + 0.5, b + f64::from(y) + 0.5)
                });
                if !region.contains(ox as f64 + centre.0 / 3.0, oy as f64 + centre.1 / 3.0) {
                    continue;
                }
                let mut t = [0u32; 3];
                for (k, (&i, &(x, y, kind))) in tri.iter().zip(&vs).enumerate() {
                    let s = &mut slot[usize::from(i)];
                    if *s == u32::MAX {
                        let (wx, wy) = (ox + i64::from(x), oy + i64::from(y));
                        let c = level.column(wx, wy);
                        let (z, ty) = match kind {
                            0 => (c.low, c.lower_type),
                            1 => (c.high, c.upper_type),
                            _ => (c.mid, c.upper_type),
                        };
                        *s = soup.positions.len() as u32;
                        soup.positions
                            .push([wx as f32 + 0.5, wy as f32 + 0.5, f32::from(z)]);
                        soup.colors.push(colors[usize::from(ty & 7)]);
                    }
                    t[k] = *s;
                }
                soup.triangles.push(t);
            }
        }
        if soup.triangles.is_empty() {
            return Err(ExportError::Empty);
        }
        Ok(soup)
    }

    /// Smallest and largest position in each axis (terrain frame).
    pub fn bounds(&self) -> ([f32; 3], [f32; 3]) {
        let mut lo = [f32::MAX; 3];
        let mut hi = [f32::MIN; 3];
        for p in &self.positions {
            for k in 0..3 {
                lo[k] = lo[k].min(p[k]);
                hi[k] = hi[k].max(p[k]);
            }
        }
        (lo, hi)
    }
}
