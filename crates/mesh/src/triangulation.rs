//! A Delaunay triangulation of grid points in an arena of triangles with
//! neighbour links, maintained by point insertion and Lawson edge flips
//! using the exact integer predicates.
//!
//! Triangles are never deleted: an insertion turns one triangle into three
//! (or two into four, for a point on an edge) and a flip rewrites two, so
//! every slot of the arena is a live triangle and no allocation happens per
//! insertion once the buffers have grown.

use crate::predicates::{Pt, incircle_small, orient2d};
use crate::samples::GapSquares;

/// No neighbour: the edge is on the chunk boundary.
pub const NONE: u32 = u32::MAX;

/// A counter-clockwise triangle. `n[i]` is the triangle across the edge
/// opposite `v[i]`, i.e. the edge `v[i+1] -> v[i+2]`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Tri {
    /// Vertex indices into [`Triangulation::pts`], counter-clockwise.
    pub v: [u32; 3],
    /// Neighbour triangle across each edge, or [`NONE`] on the boundary.
    pub n: [u32; 3],
}

/// The planar triangulation of one chunk's grid points (the arena).
#[derive(Clone, Debug, Default)]
pub struct Triangulation {
    /// Vertex positions, chunk-local sample coordinates.
    pub pts: Vec<Pt>,
    /// Per vertex: its sample is dual (has a slab): what
    /// [`is_slab`](Self::is_slab) and the outline constraints read.
    pub vdual: Vec<bool>,
    /// Keep the slab outline: never flip an edge that separates a slab
    /// triangle ([`is_slab`](Self::is_slab)) from a non-slab one. Those edges are
    /// the constraints of a constrained Delaunay triangulation; every other
    /// edge stays locally Delaunay.
    pub outline: bool,
    /// With [`outline`](Self::outline) on: the chunk's gaps, which no slab
    /// edge crosses ([`slab_edge`](Self::slab_edge)).
    pub gaps: GapSquares,
    /// With [`outline`](Self::outline) on, per triangle: bit `k` is set
    /// when its edge opposite `v[k]` is a [`slab_edge`](Self::slab_edge).
    /// Kept as triangles are written, so the many questions of the fit
    /// and the emission walk no squares.
    slab_bits: Vec<u8>,
    /// Every triangle; all slots are live.
    pub tris: Vec<Tri>,
    /// Triangles created or rewritten by the last insertion (may repeat).
    pub touched: Vec<u32>,
    stack: Vec<u32>,
    /// Edges (triangle, edge index) to check, with the outline constraints.
    edge_stack: Vec<(u32, u8)>,
}

#[inline]
fn next(i: usize) -> usize {
    if i == 2 { 0 } else { i + 1 }
}
#[inline]
fn prev(i: usize) -> usize {
    if i == 0 { 2 } else { i - 1 }
}

/// Where a point lies relative to a triangle that contains it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Location {
    /// Strictly inside the triangle.
    Inside,
    /// On the edge opposite vertex `i`.
    OnEdge(usize),
    /// Coincides with vertex `i`.
    Vertex(usize),
    /// Not in the triangle.
    Outside,
}

impl Triangulation {
    /// Reset to the rectangle `[0, sx] x [0, sy]` split along its diagonal.
    pub fn reset(&mut self, sx: i32, sy: i32) {
        self.pts.clear();
        self.vdual.clear();
        self.tris.clear();
        self.touched.clear();
        self.pts.extend([[0, 0], [sx, 0], [sx, sy], [0, sy]]);
        self.vdual.extend([false; 4]);
        // (0,1,2) and (0,2,3), both counter-clockwise.
        self.tris.push(Tri {
            v: [0, 1, 2],
            n: [NONE, 1, NONE],
        });
        self.tris.push(Tri {
            v: [0, 2, 3],
            n: [NONE, NONE, 0],
        });
        self.slab_bits.clear();
        self.slab_bits.extend([0, 0]);
    }

    /// Set whether the four corners (vertices 0 to 3) are dual, with
    /// [`outline`](Self::outline) and [`gaps`](Self::gaps) already set.
    pub fn classify_corners(&mut self, duals: [bool; 4]) {
        self.vdual[..4].copy_from_slice(&duals);
        if self.outline {
            for t in 0..self.tris.len() as u32 {
                self.slab_bits[t as usize] = self.edge_bits(t);
            }
        }
    }

    /// [`slab_bits`](Self::slab_bits) of triangle `t`, from its vertices.
    fn edge_bits(&self, t: u32) -> u8 {
        let v = self.tris[t as usize].v;
        (0..3).fold(0, |bits, k| {
            bits | u8::from(self.slab_edge(v[(k + 1) % 3], v[(k + 2) % 3])) << k
        })
    }

    /// Position of vertex `v`.
    #[inline]
    pub fn pt(&self, v: u32) -> Pt {
        self.pts[v as usize]
    }

    /// Position of `p` relative to triangle `t`, exactly.
    pub fn locate_in(&self, t: u32, p: Pt) -> Location {
        let tri = &self.tris[t as usize];
        let [a, b, c] = tri.v.map(|v| self.pt(v));
        let w = [orient2d(b, c, p), orient2d(c, a, p), orient2d(a, b, p)];
        if w.iter().any(|&w| w < 0) {
            return Location::Outside;
        }
        let zeros = w.iter().filter(|&&w| w == 0).count();
        match zeros {
            0 => Location::Inside,
            1 => Location::OnEdge(w.iter().position(|&w| w == 0).unwrap_or(0)),
            _ => Location::Vertex(w.iter().position(|&w| w != 0).unwrap_or(0)),
        }
    }

    /// Find a triangle containing `p` by scanning every triangle (used only
    /// while placing the few border vertices of an empty chunk).
    pub fn locate_scan(&self, p: Pt) -> Option<(u32, Location)> {
        // Newest first: consecutive border points along an edge usually
        // fall in a triangle the previous one just created.
        (0..self.tris.len() as u32)
            .rev()
            .find_map(|t| match self.locate_in(t, p) {
                Location::Outside => None,
                loc => Some((t, loc)),
            })
    }

    /// Insert `p`, known to lie in triangle `t` (inside or on an edge), and
    /// restore the Delaunay property. Returns the new vertex id, or `None`
    /// when `p` is not in `t` or is already a vertex.
    pub fn insert(&mut self, t: u32, p: Pt) -> Option<u32> {
        self.insert_classed(t, p, false)
    }

    /// [`insert`](Self::insert) a vertex whose sample is dual or not (what
    /// the outline constraint reads).
    pub fn insert_classed(&mut self, t: u32, p: Pt, dual: bool) -> Option<u32> {
        self.touched.clear();
        let loc = self.locate_in(t, p);
        let pv = self.pts.len() as u32;
        match loc {
            Location::Inside => {
                self.pts.push(p);
                self.vdual.push(dual);
                self.split_triangle(t, pv);
            }
            Location::OnEdge(i) => {
                self.pts.push(p);
                self.vdual.push(dual);
                self.split_edge(t, i, pv);
            }
            Location::Vertex(_) | Location::Outside => return None,
        }
        self.legalize();
        Some(pv)
    }

    /// Point the edge `a -> b` of triangle `t` (if any) at `new`.
    #[inline]
    fn relink(&mut self, t: u32, a: u32, b: u32, new: u32) {
        if t == NONE {
            return;
        }
        let tri = &mut self.tris[t as usize];
        for i in 0..3 {
            if tri.v[next(i)] == a && tri.v[prev(i)] == b {
                tri.n[i] = new;
                return;
            }
        }
    }

    /// Build the fan of triangles `(p, ring[i], ring[i+1])` into `slots`,
    /// with `outer[i]` across `ring[i] -> ring[i+1]`. A closed fan wraps.
    fn fan(&mut self, p: u32, ring: &[u32], outer: &[u32], slots: &[u32], closed: bool) {
        let m = slots.len();
        if self.outline {
            // Each spoke p-ring[i] walked once for the two triangles that
            // share it; the ring's edges (old ones) walked again.
            let mut spoke = [false; 4];
            for (s, &r) in spoke.iter_mut().zip(ring) {
                *s = self.slab_edge(p, r);
            }
            for (k, &slot) in slots.iter().enumerate() {
                let l = (k + 1) % ring.len();
                let rim = self.slab_edge(ring[k], ring[l]);
                self.slab_bits[slot as usize] =
                    u8::from(rim) | u8::from(spoke[l]) << 1 | u8::from(spoke[k]) << 2;
            }
        }
        for i in 0..m {
            let a = ring[i];
            let b = ring[(i + 1) % ring.len()];
            let nxt = if i + 1 < m {
                slots[i + 1]
            } else if closed {
                slots[0]
            } else {
                NONE
            };
            let prv = if i > 0 {
                slots[i - 1]
            } else if closed {
                slots[m - 1]
            } else {
                NONE
            };
            self.tris[slots[i] as usize] = Tri {
                v: [p, a, b],
                n: [outer[i], nxt, prv],
            };
            // The outer neighbour sees the edge as b -> a.
            self.relink(outer[i], b, a, slots[i]);
            self.stack.push(slots[i]);
            self.touched.push(slots[i]);
        }
    }

    fn new_slot(&mut self) -> u32 {
        self.tris.push(Tri {
            v: [0; 3],
            n: [NONE; 3],
        });
        self.slab_bits.push(0);
        (self.tris.len() - 1) as u32
    }

    fn split_triangle(&mut self, t: u32, p: u32) {
        let Tri { v, n } = self.tris[t as usize];
        let (s1, s2) = (self.new_slot(), self.new_slot());
        // Ring a, b, c; edge ring[i] -> ring[i+1] is opposite v[i+2].
        self.fan(
            p,
            &[v[0], v[1], v[2]],
            &[n[2], n[0], n[1]],
            &[t, s1, s2],
            true,
        );
    }

    fn split_edge(&mut self, t: u32, i: usize, p: u32) {
        let Tri { v, n } = self.tris[t as usize];
        let (c, a, b) = (v[i], v[next(i)], v[prev(i)]);
        let (n_ca, n_bc) = (n[prev(i)], n[next(i)]);
        let u = n[i];
        if u == NONE {
            // Boundary edge: the ring b, c, a around p is open.
            let s = self.new_slot();
            self.fan(p, &[b, c, a], &[n_bc, n_ca], &[t, s], false);
            return;
        }
        let ut = self.tris[u as usize];
        let j = (0..3).find(|&j| ut.n[j] == t).unwrap_or(0);
        let d = ut.v[j];
        // u = (d, b, a): across d->b is opposite a, across a->d opposite b.
        let (n_db, n_ad) = (ut.n[prev(j)], ut.n[next(j)]);
        let (s1, s2) = (self.new_slot(), self.new_slot());
        self.fan(
            p,
            &[c, a, d, b],
            &[n_ca, n_ad, n_db, n_bc],
            &[t, s1, u, s2],
            true,
        );
    }

    /// Lawson flips from the edges opposite the new point: every triangle on
    /// the stack has the new point at `v[0]`, its suspect edge opposite it.
    fn legalize(&mut self) {
        if self.outline {
            self.legalize_constrained();
            return;
        }
        while let Some(t) = self.stack.pop() {
            let tri = self.tris[t as usize];
            let u = tri.n[0];
            if u == NONE {
                continue;
            }
            let ut = self.tris[u as usize];
            let Some(j) = (0..3).find(|&j| ut.n[j] == t) else {
                continue;
            };
            let [p, a, b] = tri.v;
            let d = ut.v[j];
            // Flip only when d is strictly inside: cocircular quads keep their
            // current diagonal, which makes the result a deterministic
            // function of the insertion order.
            if incircle_small(self.pt(p), self.pt(a), self.pt(b), self.pt(d)) <= 0 {
                continue;
            }
            self.flip(t, 0, u, j);
            self.stack.push(t);
            self.stack.push(u);
            self.touched.push(t);
            self.touched.push(u);
        }
    }

    /// [`legalize`](Self::legalize) with the outline constraints. Whether an
    /// edge is a constraint depends on the vertices opposite it, which a
    /// flip changes for all four outer edges of its quad; so every one of
    /// them is checked again, not only the two opposite the new point (the
    /// plain rule relies on every edge being Delaunay, which constraints
    /// are not). Each
    /// flip removes an edge whose opposite vertex lies strictly inside the
    /// circumcircle, which lowers the lifted triangulation: it terminates,
    /// and leaves every edge but the constraints locally Delaunay.
    fn legalize_constrained(&mut self) {
        // The edges opposite the new point, and where it split an edge,
        // that edge's two halves: they face new vertices across what may
        // have been a constraint, so not a Delaunay edge. (A new edge to a
        // vertex of the split triangle is locally Delaunay: the circle
        // through it and the third vertex on one side lies inside the old
        // triangle's circumcircle there.)
        self.edge_stack.clear();
        self.edge_stack.extend(self.stack.iter().map(|&t| (t, 0u8)));
        if self.stack.len() == 4 {
            // Closed fan (p,c,a), (p,a,d), (p,d,b), (p,b,c): the halves p-a
            // and p-b are edge 1 of the first and the third.
            self.edge_stack
                .extend([(self.stack[0], 1), (self.stack[2], 1)]);
        }
        self.stack.clear();
        while let Some((t, i)) = self.edge_stack.pop() {
            let i = usize::from(i);
            let tri = self.tris[t as usize];
            let u = tri.n[i];
            if u == NONE {
                continue;
            }
            let ut = self.tris[u as usize];
            let Some(j) = (0..3).find(|&j| ut.n[j] == t) else {
                continue;
            };
            let (p, a, b) = (tri.v[i], tri.v[next(i)], tri.v[prev(i)]);
            let d = ut.v[j];
            if self.is_outline_edge(t, i, u)
                || incircle_small(self.pt(p), self.pt(a), self.pt(b), self.pt(d)) <= 0
            {
                continue;
            }
            self.flip(t, i, u, j);
            // a-d, d-b, p-a, b-p.
            self.edge_stack.extend([(t, 0), (u, 0), (t, 2), (u, 1)]);
            self.touched.push(t);
            self.touched.push(u);
        }
    }

    /// Flip the edge a-b between triangle `t` (p, a, b, with p its vertex
    /// `i`) and its neighbour `u` across it (d, its vertex `j`): `t` becomes
    /// (p, a, d) and `u` (p, d, b), neighbours relinked.
    fn flip(&mut self, t: u32, i: usize, u: u32, j: usize) {
        let (tri, ut) = (self.tris[t as usize], self.tris[u as usize]);
        let (p, a, b) = (tri.v[i], tri.v[next(i)], tri.v[prev(i)]);
        let d = ut.v[j];
        let (n_ad, n_db) = (ut.n[next(j)], ut.n[prev(j)]);
        let (n_bp, n_pa) = (tri.n[next(i)], tri.n[prev(i)]);
        if self.outline {
            // Four edges keep their bits; the new diagonal p-d is walked.
            let bit = |bits: u8, k: usize| bits >> k & 1;
            let (bt, bu) = (self.slab_bits[t as usize], self.slab_bits[u as usize]);
            let (ad, db) = (bit(bu, next(j)), bit(bu, prev(j)));
            let (bp, pa) = (bit(bt, next(i)), bit(bt, prev(i)));
            let pd = u8::from(self.slab_edge(p, d));
            self.slab_bits[t as usize] = ad | pd << 1 | pa << 2;
            self.slab_bits[u as usize] = db | bp << 1 | pd << 2;
        }
        self.tris[t as usize] = Tri {
            v: [p, a, d],
            n: [n_ad, u, n_pa],
        };
        self.tris[u as usize] = Tri {
            v: [p, d, b],
            n: [n_db, n_bp, t],
        };
        self.relink(n_ad, d, a, t);
        self.relink(n_bp, p, b, u);
    }

    /// With [`outline`](Self::outline) on: does edge `i` of triangle `t`,
    /// with `u` across it, separate a slab triangle from a non-slab one?
    #[inline]
    fn is_outline_edge(&self, t: u32, i: usize, u: u32) -> bool {
        self.outline
            && self.slab_bits[t as usize] >> i & 1 == 1
            && self.is_slab(t) != self.is_slab(u)
    }

    /// Can segment `a`-`b` bound a slab triangle? Both ends are dual and,
    /// in the outline fit, it passes over no unit square without a dual
    /// corner: every point of it lies within half a texel of a slab column.
    /// Two rims of a canyon are dual at both ends, yet the segment between
    /// them crosses the gap; a thin triangle on it covers no sample there
    /// for the error to see, and its walls would stand across the gap.
    #[inline]
    pub fn slab_edge(&self, a: u32, b: u32) -> bool {
        self.vdual[a as usize]
            && self.vdual[b as usize]
            && (!self.outline || self.gaps.clear(self.pt(a), self.pt(b)))
    }

    /// Is triangle `t` a slab triangle: all three vertices dual and, in the
    /// outline fit, every edge a [`slab_edge`](Self::slab_edge)?
    #[inline]
    pub fn is_slab(&self, t: u32) -> bool {
        if self.outline {
            self.slab_bits[t as usize] == 0b111
        } else {
            self.tris[t as usize]
                .v
                .iter()
                .all(|&v| self.vdual[v as usize])
        }
    }

    /// Per edge of triangle `t` (the edge opposite vertex `k`): is it a
    /// [`slab_edge`](Self::slab_edge)?
    #[inline]
    pub fn slab_edges(&self, t: u32) -> [bool; 3] {
        if self.outline {
            let bits = self.slab_bits[t as usize];
            [0, 1, 2].map(|k| bits >> k & 1 == 1)
        } else {
            let v = self.tris[t as usize].v;
            [0, 1, 2].map(|k| self.slab_edge(v[(k + 1) % 3], v[(k + 2) % 3]))
        }
    }

    /// Edges whose opposite vertex lies strictly inside the circumcircle of
    /// the triangle across (should be none; outline constraints excepted).
    /// For tests and debug checks.
    pub fn delaunay_violations(&self) -> usize {
        let mut bad = 0;
        for (t, tri) in self.tris.iter().enumerate() {
            for i in 0..3 {
                let u = tri.n[i];
                if u == NONE {
                    continue;
                }
                let ut = &self.tris[u as usize];
                let Some(j) = (0..3).find(|&j| ut.n[j] == t as u32) else {
                    bad += 1;
                    continue;
                };
                let [a, b, c] = tri.v.map(|v| self.pt(v));
                if self.is_outline_edge(t as u32, i, u) {
                    continue;
                }
                if crate::predicates::incircle(a, b, c, self.pt(ut.v[j])) > 0 {
                    bad += 1;
                }
            }
        }
        bad
    }

    /// Structural check: counter-clockwise, non-degenerate, symmetric links.
    pub fn is_consistent(&self) -> bool {
        self.tris.iter().enumerate().all(|(t, tri)| {
            let [a, b, c] = tri.v.map(|v| self.pt(v));
            orient2d(a, b, c) > 0
                && (0..3).all(|i| {
                    let u = tri.n[i];
                    u == NONE || {
                        let ut = &self.tris[u as usize];
                        (0..3).any(|j| {
                            ut.n[j] == t as u32
                                && ut.v[next(j)] == tri.v[prev(i)]
                                && ut.v[prev(j)] == tri.v[next(i)]
                        })
                    }
                })
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn inserting_every_grid_point_stays_delaunay_and_consistent() {
        let mut tr = Triangulation::default();
        tr.reset(8, 8);
        // Boundary points first (as the fitter does), then the interior in a
        // scrambled but fixed order: the grid is all cocircular quads.
        let mut order: Vec<Pt> = Vec::new();
        for k in 1..8 {
            order.extend([[k, 0], [8, k], [k, 8], [0, k]]);
        }
        let mut interior: Vec<Pt> = (1..8).flat_map(|y| (1..8).map(move |x| [x, y])).collect();
        interior.sort_by_key(|p| (p[0] * 31 + p[1] * 17) % 49);
        order.extend(interior);
        for p in order {
            let (t, loc) = tr.locate_scan(p).expect("inside the square");
            assert!(matches!(loc, Location::Inside | Location::OnEdge(_)));
            assert!(tr.insert(t, p).is_some());
            assert!(tr.is_consistent());
            assert_eq!(tr.delaunay_violations(), 0);
        }
        assert_eq!(tr.pts.len(), 81);
        // A full triangulation of a 9x9 grid has 2 * 8 * 8 triangles.
        assert_eq!(tr.tris.len(), 128);
    }

    #[test]
    fn inserting_a_vertex_twice_is_refused() {
        let mut tr = Triangulation::default();
        tr.reset(4, 4);
        let (t, _) = tr.locate_scan([4, 4]).unwrap();
        assert_eq!(tr.insert(t, [4, 4]), None);
        assert_eq!(tr.insert(0, [-1, 0]), None);
    }
}
