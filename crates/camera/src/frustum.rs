//! The part of a camera's view that can hold terrain, as points and their
//! outline: the forward methods' footprint, the scattered grid and the
//! shadow map's cover all start from it.

use crate::Camera;
use glam::Vec3;

/// Points whose convex hull is the part of `camera`'s frustum (view depth
/// near to `far`) with altitude in `0..=top`; empty when the frustum misses
/// that range. A convex body cut by a slab has for vertices the body's own
/// vertices inside the slab and the crossings of its edges with the slab's
/// two planes.
pub fn slab_points(camera: &Camera, far: f32, top: f32) -> Vec<Vec3> {
    let (w, h) = (camera.width as f32, camera.height as f32);
    let image = [(0.0, 0.0), (w, 0.0), (w, h), (0.0, h)];
    // Corners at view depth `d`: the image direction's forward part is the focal length.
    let corners = |d: f32| {
        image.map(|(px, py)| {
            camera.position + camera.image_direction(px, py) * (d / camera.focal_px)
        })
    };
    let (near, far) = (corners(camera.near), corners(far));
    let mut points: Vec<Vec3> = near
        .iter()
        .chain(&far)
        .copied()
        .filter(|p| (0.0..=top).contains(&p.z))
        .collect();
    for i in 0..4 {
        let j = (i + 1) % 4;
        for (a, b) in [(near[i], near[j]), (far[i], far[j]), (near[i], far[i])] {
            for z in [0.0, top] {
                if (a.z - z) * (b.z - z) < 0.0 {
                    points.push(a.lerp(b, (z - a.z) / (b.z - a.z)));
                }
            }
        }
    }
    points
}

/// Counter-clockwise convex hull of `points` (Andrew's monotone chain);
/// points inside or on an edge are dropped.
pub fn convex_hull(mut points: Vec<[f32; 2]>) -> Vec<[f32; 2]> {
    points.sort_by(|p, q| p[0].total_cmp(&q[0]).then(p[1].total_cmp(&q[1])));
    points.dedup();
    if points.len() < 3 {
        return points;
    }
    let turn = |o: [f32; 2], a: [f32; 2], b: [f32; 2]| {
        (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])
    };
    let mut hull: Vec<[f32; 2]> = Vec::with_capacity(2 * points.len());
    for reverse in [false, true] {
        let start = hull.len();
        let ordered: Box<dyn Iterator<Item = &[f32; 2]>> = if reverse {
            Box::new(points.iter().rev())
        } else {
            Box::new(points.iter())
        };
        for &p in ordered {
            while hull.len() >= start + 2
                && turn(hull[hull.len() - 2], hull[hull.len() - 1], p) <= 0.0
            {
                hull.pop();
            }
            hull.push(p);
        }
        hull.pop();
    }
    hull
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hull_drops_inner_and_collinear_points() {
        let pts = vec![
            [0.0, 0.0],
            [2.0, 0.0],
            [1.0, 0.0],
            [2.0, 2.0],
            [0.0, 2.0],
            [1.0, 1.0],
        ];
        let h = convex_hull(pts);
        assert_eq!(h, vec![[0.0, 0.0], [2.0, 0.0], [2.0, 2.0], [0.0, 2.0]]);
    }

    #[test]
    fn a_level_view_cut_to_the_slab_reaches_the_far_plane() {
        let camera = Camera::new(Vec3::new(100.0, 100.0, 50.0), 0.0, 0.0, 320, 200).unwrap();
        let points = slab_points(&camera, camera.far, 255.0);
        // Crossings are interpolated in f32: on the planes to rounding.
        assert!(points.iter().all(|p| (-1e-3..=255.001).contains(&p.z)));
        let reach = points
            .iter()
            .map(|p| (*p - camera.position).dot(camera.basis().forward))
            .fold(0.0, f32::max);
        assert!((reach - camera.far).abs() < 1e-2, "reach {reach}");
        // Above the slab: nothing.
        let high = Camera::new(Vec3::new(0.0, 0.0, 900.0), 0.0, 30.0, 320, 200).unwrap();
        assert!(slab_points(&high, high.far, 255.0).is_empty());
    }
}
