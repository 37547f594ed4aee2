//! Contact surfaces: parry3d height fields over texel-centre samples, one
//! per surface of the two-interval model, built on demand for a rectangle
//! of samples (a chunk around a body, or a query's footprint).
//!
//! - the floor: every column's `low` (the ground, or a cave's floor);
//! - the slab top: `high` of dual columns;
//! - the slab underside (a cave's ceiling): `mid` of dual columns.
//!
//! A slab cell (four samples) exists where at least one of its corners is
//! dual; its single corners take their own top, so a slab's surfaces meet
//! the ground around it. Cells with no dual corner are removed from the
//! slab surfaces. Samples stand at texel centres `(x + 0.5, y + 0.5)`, the
//! frame the renderer draws and the former triangle mesh used.

use crate::columns::{Columns, Packed};
use parry3d::math::{Pose, Rotation, Vector};
use parry3d::shape::{HeightField, HeightFieldCellStatus, HeightFieldFlags};
use parry3d::utils::Array2;

/// The height fields over samples `x0..=x0 + nx`, `y0..=y0 + ny` (texel
/// indices, unwrapped).
pub struct Surfaces {
    /// The floor (always there).
    pub floor: HeightField,
    /// The slab top, where a cell touches a dual column.
    pub slab_top: Option<HeightField>,
    /// The slab underside (cave ceiling), where a cell touches a dual column.
    pub ceiling: Option<HeightField>,
    /// Where the fields sit: translate by this and rotate by
    /// [`Surfaces::rotation`] (parry's height fields are y-up).
    pub centre: [f64; 3],
}

impl Surfaces {
    /// The rotation taking a height field's y-up frame to the world's z-up
    /// one: a quarter turn about x (local y -> world z, local z -> world -y).
    pub fn rotation() -> Rotation {
        Rotation::from_rotation_x(std::f32::consts::FRAC_PI_2)
    }

    /// The fields' pose in a frame whose origin is the world point `origin`.
    pub fn pose(&self, origin: [f64; 3]) -> Pose {
        Self::pose_of(self.centre, origin)
    }

    /// The pose of fields centred at `centre`, in the frame at `origin`.
    pub(crate) fn pose_of(centre: [f64; 3], origin: [f64; 3]) -> Pose {
        Pose::from_parts(
            Vector::new(
                (centre[0] - origin[0]) as f32,
                (centre[1] - origin[1]) as f32,
                (centre[2] - origin[2]) as f32,
            ),
            Self::rotation(),
        )
    }

    /// The fields present, floor first.
    pub fn fields(&self) -> impl Iterator<Item = &HeightField> {
        std::iter::once(&self.floor)
            .chain(self.slab_top.as_ref())
            .chain(self.ceiling.as_ref())
    }

    /// Bytes held by the fields.
    pub fn memory_bytes(&self) -> usize {
        self.fields()
            .map(|f| f.heights().data().len() * 4 + f.cells_statuses().data().len())
            .sum()
    }
}

impl Columns {
    /// The surfaces over samples `x0..=x0 + nx`, `y0..=y0 + ny` (`nx`, `ny`
    /// at least 1), every `step`-th sample (`step` divides both; 1: every
    /// sample, exact).
    pub(crate) fn surfaces(&self, x0: i64, y0: i64, nx: u32, ny: u32, step: u32) -> Surfaces {
        let (rows, cols) = ((ny / step) as usize + 1, (nx / step) as usize + 1);
        let st = i64::from(step);
        // Row i is texel row y0 + ny - i step (local z runs to world -y);
        // column j is texel column x0 + j step. Column-major, as parry's Array2.
        let sample =
            |i: usize, j: usize| self.get(x0 + j as i64 * st, y0 + i64::from(ny) - i as i64 * st);
        let mut floor = Vec::with_capacity(rows * cols);
        let mut top = Vec::with_capacity(rows * cols);
        let mut under = Vec::with_capacity(rows * cols);
        let mut dual = Vec::with_capacity(rows * cols);
        for j in 0..cols {
            for i in 0..rows {
                let c: Packed = sample(i, j);
                floor.push(f32::from(c.low()));
                top.push(f32::from(c.top()));
                under.push(f32::from(if c.dual() { c.mid() } else { c.low() }));
                dual.push(c.dual());
            }
        }
        let scale = Vector::new(nx as f32, 1.0, ny as f32);
        let centre = [
            x0 as f64 + 0.5 + f64::from(nx) * 0.5,
            y0 as f64 + 0.5 + f64::from(ny) * 0.5,
            0.0,
        ];
        // Contacts on a shared edge of two coplanar triangles take the faces'
        // normal (without it, balls on flat ground roll off the texel grid).
        let field = |h: Vec<f32>| {
            HeightField::with_flags(
                Array2::new(rows, cols, h),
                scale,
                HeightFieldFlags::FIX_INTERNAL_EDGES,
            )
        };
        let any_dual = dual.iter().any(|&d| d);
        let slab = |h: Vec<f32>| {
            let mut f = field(h);
            let status = f.cells_statuses_mut();
            for j in 0..cols - 1 {
                for i in 0..rows - 1 {
                    let corner = |i: usize, j: usize| dual[i + j * rows];
                    if !(corner(i, j)
                        || corner(i + 1, j)
                        || corner(i, j + 1)
                        || corner(i + 1, j + 1))
                    {
                        status[(i, j)] = HeightFieldCellStatus::CELL_REMOVED;
                    }
                }
            }
            f
        };
        Surfaces {
            floor: field(floor),
            slab_top: any_dual.then(|| slab(top)),
            ceiling: any_dual.then(|| slab(under)),
            centre,
        }
    }
}
