//! The region's triangles as an indexed, coloured triangle list.

use crate::color::type_colors;
use crate::error::ExportError;
use crate::region::Region;
use std::collections::HashMap;
use strata_level::World;
use strata_level::source::ColumnSource;
use strata_mesh::region::{cell_chunk, fit_chunks_from, layout_for, region_cells};
use strata_mesh::{ChunkMesh, FitOptions, decode, tolerance_for_quality};

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
        Self::build_from(&world.level, world, region, q)
    }

    /// [`TerrainSoup::build`] over the map `source` reads (a store's chunk
    /// cache: only the chunks under the region are read), with `world`'s
    /// colours (its level is not read). Equal to the in-memory export.
    pub fn build_from(
        source: &dyn ColumnSource,
        world: &World,
        region: Region,
        q: f64,
    ) -> Result<Self, ExportError> {
        let tol = tolerance_for_quality(q).ok_or(ExportError::Quality(q))?;
        let (w, h) = source.size();
        let layout = layout_for(w, h);
        let (sx, sy) = (i64::from(layout.size_x), i64::from(layout.size_y));
        let cell_list = region_cells(&layout, region.x0, region.y0, region.x1, region.y1);
        let chunk_of = |gx: i64, gy: i64| cell_chunk(&layout, gx, gy);
        let mut ids: Vec<usize> = cell_list.iter().map(|&(x, y)| chunk_of(x, y)).collect();
        ids.sort_unstable();
        ids.dedup();
        let fitted = fit_chunks_from(source, &layout, &ids, tol, FitOptions::default())?;
        let meshes: HashMap<usize, ChunkMesh> = ids.into_iter().zip(fitted).collect();
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
                        let c = source.column(wx, wy)?;
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
