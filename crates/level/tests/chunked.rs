//! The chunked generator (worlds past memory, written into stores) makes
//! the same bytes as the in-memory one wherever both apply, rectangle by
//! rectangle, and refuses bad sizes and rectangles with errors.

use strata_level::World;
use strata_level::generate::{
    Chunked, GenerateError, GenerateParams, Knobs, generate_with, landmark_list,
};

/// The whole map through `fill`, in `cw x ch` rectangles.
fn by_rects(c: &Chunked, cw: u32, ch: u32) -> (Vec<u8>, Vec<u8>) {
    let GenerateParams { width, height, .. } = *c.params();
    let w = width as usize;
    let mut heights = vec![0u8; w * height as usize];
    let mut metas = heights.clone();
    for y0 in (0..height).step_by(ch as usize) {
        for x0 in (0..width).step_by(cw as usize) {
            let (cols, rows) = (cw.min(width - x0), ch.min(height - y0));
            let n = (cols * rows) as usize;
            let (mut hb, mut mb) = (vec![0u8; n], vec![0u8; n]);
            c.fill((x0, y0, cols, rows), &mut hb, &mut mb).unwrap();
            for r in 0..rows as usize {
                let dst = (y0 as usize + r) * w + x0 as usize;
                let src = r * cols as usize..(r + 1) * cols as usize;
                heights[dst..dst + cols as usize].copy_from_slice(&hb[src.clone()]);
                metas[dst..dst + cols as usize].copy_from_slice(&mb[src]);
            }
        }
    }
    (heights, metas)
}

fn same_world(params: GenerateParams, knobs: Knobs, rects: &[(u32, u32)]) {
    let whole: World = generate_with(&params, &knobs).unwrap();
    let c = Chunked::new(&params, &knobs).unwrap();
    for &(cw, ch) in rects {
        let (h, m) = by_rects(&c, cw, ch);
        let (wh, wm) = (whole.level.heights(), whole.level.metas());
        assert!(
            h == wh && m == wm,
            "{params:?} {knobs:?} in {cw}x{ch} rectangles differs from the in-memory world"
        );
    }
    let shell = c.world_without_planes();
    assert_eq!(shell.name, whole.name);
    assert_eq!(shell.views, whole.views);
    assert_eq!(shell.edit, whole.edit);
    assert_eq!(shell.water, whole.water);
    assert_eq!(shell.config.to_ini_bytes(), whole.config.to_ini_bytes());
    assert_eq!(c.landmarks(), landmark_list(&params).unwrap());
}

#[test]
fn chunked_equals_in_memory() {
    let p = |seed, width, height| GenerateParams {
        seed,
        width,
        height,
    };
    // Chunks of a store (256²), odd-shaped rectangles that cut through
    // landmarks, districts and the coarse lattice, and whole rows.
    same_world(
        p(1997, 1024, 2048),
        Knobs::default(),
        &[(256, 256), (98, 37), (1024, 5)],
    );
    same_world(p(3, 256, 256), Knobs::default(), &[(256, 256), (6, 250)]);
    same_world(
        p(8, 512, 1024),
        Knobs {
            dual_fraction: Some(0.3),
            floor_roughness: Some(2.5),
        },
        &[(256, 256), (130, 77)],
    );
    same_world(
        p(8, 1024, 256),
        Knobs {
            dual_fraction: None,
            floor_roughness: Some(0.0),
        },
        &[(256, 256)],
    );
}

#[test]
fn a_patch_wraps_like_the_map() {
    let params = GenerateParams {
        seed: 5,
        width: 512,
        height: 512,
    };
    let whole = generate_with(&params, &Knobs::default()).unwrap();
    let c = Chunked::new(&params, &Knobs::default()).unwrap();
    // Across both seams; x rounds down to even.
    let patch = c.patch(-63, 500, 128, 64).unwrap();
    for y in 0..64 {
        for x in 0..128 {
            assert_eq!(
                patch.column(x, y),
                whole.level.column(x - 64, y + 500),
                "({x}, {y})"
            );
        }
    }
}

#[test]
fn bad_sizes_and_rectangles_are_errors() {
    for (width, height) in [(300, 512), (128, 512), (1 << 17, 256), (256, 0)] {
        let err = Chunked::new(
            &GenerateParams {
                seed: 1,
                width,
                height,
            },
            &Knobs::default(),
        )
        .err()
        .unwrap();
        assert!(matches!(err, GenerateError::Size { .. }), "{err}");
    }
    let knobs = Knobs {
        dual_fraction: Some(0.9),
        floor_roughness: None,
    };
    assert!(matches!(
        Chunked::new(&GenerateParams::default(), &knobs).err(),
        Some(GenerateError::Knob { .. })
    ));
    // 65536 a side is accepted (placing the landmarks needs no map).
    let big = Chunked::new(
        &GenerateParams {
            seed: 1,
            width: 1 << 16,
            height: 1 << 16,
        },
        &Knobs::default(),
    )
    .unwrap();
    assert_eq!(big.world_without_planes().views.len(), 12);
    let mut b = vec![0u8; 16];
    for rect in [
        (1, 0, 4, 4),
        (0, 0, 3, 4),
        (65534, 0, 4, 4),
        (0, 65535, 4, 4),
        (0, 0, 4, 5),
    ] {
        let mut m = b.clone();
        let err = big.fill(rect, &mut b, &mut m).unwrap_err();
        assert!(matches!(err, GenerateError::Rect { .. }), "{rect:?}: {err}");
    }
    assert!(big.patch(0, 0, 3, 4).is_err());
    assert!(big.patch(0, 0, 4, 1 << 17).is_err());
}
