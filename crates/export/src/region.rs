//! The texel rectangle to export, on the wrapping map.

use crate::error::ExportError;
use strata_level::Level;

/// A half-open texel rectangle `[x0, x1) x [y0, y1)` in unwrapped
/// coordinates. The map is a torus: `x0, y0` lie inside the map and
/// `x1, y1` may pass its far edge, in which case the region continues at
/// the map's start and the export keeps it in one piece at unwrapped
/// coordinates (`1900,0,2148,64` on a 2048-wide map is texels 1900..2047
/// then 0..99, written at x = 1900..2148). A region is at most one map size
/// in each direction.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Region {
    /// First texel column.
    pub x0: i64,
    /// First texel row.
    pub y0: i64,
    /// One past the last column.
    pub x1: i64,
    /// One past the last row.
    pub y1: i64,
}

impl Region {
    /// The whole map.
    pub fn whole(level: &Level) -> Self {
        Self::whole_of(level.width(), level.height())
    }

    /// The whole of a `width x height` map.
    pub fn whole_of(width: u32, height: u32) -> Self {
        Region {
            x0: 0,
            y0: 0,
            x1: i64::from(width),
            y1: i64::from(height),
        }
    }

    /// Parse `X0,Y0,X1,Y1` and check it against the map. The map wraps:
    /// `X1,Y1` may pass its edge (the piece across it is exported at
    /// unwrapped coordinates), `X0,Y0` must lie inside it.
    ///
    /// ```
    /// use strata_export::Region;
    /// let level = strata_level::Level::flat(256, 256, 40, 1).unwrap();
    /// // Across the right edge: columns 200..300 are 200..255 then 0..43.
    /// let r = Region::parse("200,0,300,64", &level).unwrap();
    /// assert!(r.contains(290.0, 10.0));
    /// // Outside the map: a clear error naming the text and the map's size.
    /// let e = Region::parse("300,0,400,64", &level).unwrap_err();
    /// assert!(e.to_string().contains("300,0,400,64"));
    /// assert_eq!(Region::whole(&level).x1, 256);
    /// ```
    pub fn parse(text: &str, level: &Level) -> Result<Self, ExportError> {
        Self::parse_in(text, level.width(), level.height())
    }

    /// [`Region::parse`] against a `width x height` map (one not in memory).
    pub fn parse_in(text: &str, width: u32, height: u32) -> Result<Self, ExportError> {
        let v: Vec<i64> = text
            .split(',')
            .map(|s| s.trim().parse::<i64>())
            .collect::<Result<_, _>>()
            .map_err(|_| ExportError::RegionSyntax(text.to_string()))?;
        let [x0, y0, x1, y1] = v[..] else {
            return Err(ExportError::RegionSyntax(text.to_string()));
        };
        let (w, h) = (i64::from(width), i64::from(height));
        let bad = |why| ExportError::RegionBounds {
            text: text.to_string(),
            why,
            width,
            height,
        };
        if x0 >= x1 || y0 >= y1 {
            return Err(bad("empty (X1 must exceed X0 and Y1 exceed Y0)"));
        }
        if !(0..w).contains(&x0) || !(0..h).contains(&y0) {
            return Err(bad("X0,Y0 outside the map"));
        }
        if x1 - x0 > w || y1 - y0 > h {
            return Err(bad("wider or taller than the map"));
        }
        Ok(Region { x0, y0, x1, y1 })
    }

    /// Does the region hold the point `(x, y)` (unwrapped)?
    pub fn contains(&self, x: f64, y: f64) -> bool {
        x >= self.x0 as f64 && x < self.x1 as f64 && y >= self.y0 as f64 && y < self.y1 as f64
    }
}
