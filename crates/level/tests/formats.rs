//! Map formats: round trips, a real (non-identity) Huffman code, and bad input.

mod common;

use common::{synthetic, temp_dir};
use std::path::Path;
use strata_level::huffman::TREE_SLOTS;
use strata_level::model::MidRule;
use strata_level::vmc::{decode_vmc, encode_vmc, header_bytes};
use strata_level::vmp::{decode_vmp, encode_vmp};
use strata_level::{Level, LevelError};

const P: &str = "t/output.vmc";

fn decode(bytes: &[u8], w: u32, h: u32) -> Result<Level, LevelError> {
    decode_vmc(bytes, w, h, MidRule::Original, Path::new(P))
}

fn row_entry(bytes: &[u8], y: usize) -> (usize, usize) {
    let e = &bytes[y * 6..y * 6 + 6];
    (
        i32::from_le_bytes([e[0], e[1], e[2], e[3]]) as usize,
        i16::from_le_bytes([e[4], e[5]]) as usize,
    )
}

fn set_row_entry(bytes: &mut [u8], y: usize, offset: i32, size: i16) {
    bytes[y * 6..y * 6 + 4].copy_from_slice(&offset.to_le_bytes());
    bytes[y * 6 + 4..y * 6 + 6].copy_from_slice(&size.to_le_bytes());
}

fn err_text(r: Result<Level, LevelError>) -> String {
    match r {
        Ok(_) => panic!("expected an error"),
        Err(e) => e.to_string(),
    }
}

#[test]
fn vmc_round_trip_is_byte_identical() {
    for (w, h, seed) in [(64, 32, 1), (256, 128, 2), (2, 1, 3)] {
        let level = synthetic(w, h, seed);
        assert!(
            level.dual_texel_count() > 0 || w == 2,
            "the fixture needs dual pairs"
        );
        let bytes = encode_vmc(&level, Path::new(P)).unwrap();
        let back = decode(&bytes, w, h).unwrap();
        assert!(
            back.heights() == level.heights(),
            "heights differ ({w}x{h})"
        );
        assert!(back.metas() == level.metas(), "metas differ ({w}x{h})");
    }
}

#[test]
fn vmp_round_trip_is_byte_identical() {
    let level = synthetic(128, 64, 9);
    let bytes = encode_vmp(&level);
    assert_eq!(bytes.len(), 2 * 128 * 64);
    // Row layout: W heights then W metas.
    assert_eq!(&bytes[..128], &level.heights()[..128]);
    assert_eq!(&bytes[128..256], &level.metas()[..128]);
    let back = decode_vmp(&bytes, 128, 64, MidRule::Original, Path::new("a.vmp")).unwrap();
    assert!(back == level);
}

#[test]
fn vmc_uses_a_real_huffman_code_and_compresses() {
    let level = synthetic(256, 256, 4);
    let bytes = encode_vmc(&level, Path::new(P)).unwrap();
    let raw = 2 * 256 * 256;
    assert!(
        bytes.len() < raw * 6 / 10,
        "{} bytes for {raw} raw",
        bytes.len()
    );
    // The height tree is not the 8-bit identity tree: some symbol sits at depth != 8.
    let tree_at = 256 * 6;
    let tree: Vec<i32> = bytes[tree_at..tree_at + TREE_SLOTS * 4]
        .chunks_exact(4)
        .map(|b| i32::from_le_bytes([b[0], b[1], b[2], b[3]]))
        .collect();
    let mut depth_of_first_leaf = 0;
    let mut node = 1usize;
    loop {
        depth_of_first_leaf += 1;
        let v = tree[2 * node];
        if v <= 0 {
            break;
        }
        node = v as usize;
    }
    assert!(depth_of_first_leaf < 8, "depth {depth_of_first_leaf}");
}

#[test]
fn truncated_vmc_is_an_error() {
    let level = synthetic(64, 32, 5);
    let bytes = encode_vmc(&level, Path::new(P)).unwrap();
    let e = err_text(decode(&bytes[..100], 64, 32));
    assert!(e.starts_with(P) && e.contains("truncated"), "{e}");
    let e = err_text(decode(&bytes[..bytes.len() - 1], 64, 32));
    assert!(e.contains("row 31") && e.contains("past the end"), "{e}");
}

#[test]
fn row_table_past_the_end_is_an_error() {
    let level = synthetic(64, 32, 6);
    let mut bytes = encode_vmc(&level, Path::new(P)).unwrap();
    let len = bytes.len() as i32;
    set_row_entry(&mut bytes, 3, len - 2, 100);
    let e = err_text(decode(&bytes, 64, 32));
    assert!(e.contains("row 3") && e.contains("past the end"), "{e}");
    set_row_entry(&mut bytes, 3, -5, 10);
    let e = err_text(decode(&bytes, 64, 32));
    assert!(e.contains("row 3") && e.contains("negative"), "{e}");
}

#[test]
fn rows_must_fill_exactly_their_size() {
    let level = synthetic(64, 32, 7);
    let mut bytes = encode_vmc(&level, Path::new(P)).unwrap();
    let (off, size) = row_entry(&bytes, 5);
    set_row_entry(&mut bytes, 5, off as i32, size as i16 + 1);
    let e = err_text(decode(&bytes, 64, 32));
    assert!(e.contains("row 5") && e.contains("fill only"), "{e}");
    // One byte short: the meta stream runs past the row.
    assert!(size > 16, "the fixture's rows are longer than the minimum");
    set_row_entry(&mut bytes, 5, off as i32, size as i16 - 1);
    let e = err_text(decode(&bytes, 64, 32));
    assert!(e.contains("row 5") && e.contains("runs past"), "{e}");
    // Below the minimum a row can hold at all.
    set_row_entry(&mut bytes, 5, off as i32, 1);
    let e = err_text(decode(&bytes, 64, 32));
    assert!(e.contains("row 5") && e.contains("cannot hold"), "{e}");
}

#[test]
fn cyclic_and_out_of_range_trees_are_errors() {
    let level = synthetic(64, 32, 8);
    let bytes = encode_vmc(&level, Path::new(P)).unwrap();
    let meta_tree = 32 * 6 + TREE_SLOTS * 4;
    for (value, expected) in [(1i32, "reached twice"), (4000, "outside 1..=255")] {
        let mut bad = bytes.clone();
        // Slot 2 (node 1, bit 0) of the meta tree.
        bad[meta_tree + 8..meta_tree + 12].copy_from_slice(&value.to_le_bytes());
        let e = err_text(decode(&bad, 64, 32));
        assert!(
            e.starts_with(P) && e.contains("meta Huffman tree") && e.contains(expected),
            "{e}"
        );
    }
}

#[test]
fn map_size_disagreeing_with_the_file_is_an_error() {
    let level = synthetic(64, 32, 10);
    let bytes = encode_vmc(&level, Path::new(P)).unwrap();
    // Twice the rows: the table would overlap the rows.
    let e = err_text(decode(&bytes, 64, 64));
    assert!(e.contains("map size") || e.contains("truncated"), "{e}");
    // Wider rows: the streams do not fit.
    let e = err_text(decode(&bytes, 128, 32));
    assert!(e.contains("row 0"), "{e}");
    // Far wider rows: refused from the table alone, before allocating.
    let e = err_text(decode(&bytes, 1 << 15, 32));
    assert!(
        e.contains("row 0") && e.contains("cannot hold 32768 heights"),
        "{e}"
    );
    let e = err_text(decode_vmp(
        &encode_vmp(&level),
        64,
        64,
        MidRule::Original,
        Path::new("a.vmp"),
    ));
    assert!(e.contains("a.vmp") && e.contains("disagrees"), "{e}");
    assert_eq!(header_bytes(32), 32 * 6 + 4096);
}

#[test]
fn world_directory_round_trip() {
    use strata_level::io::{load_world, write_world};
    use strata_level::{EditSite, World, WorldConfig};
    let dir = temp_dir("world_round_trip");
    let level = synthetic(64, 256, 11);
    for compressed in [true, false] {
        let world = World {
            name: "x".into(),
            level: level.clone(),
            config: WorldConfig {
                map_power_x: 6,
                map_power_y: 8,
                compressed,
                file_name: "mine".into(),
                palette_file: "mine.pal".into(),
                ..WorldConfig::default()
            },
            palette: strata_level::Palette {
                colors: std::array::from_fn(|i| [(i % 64 * 4) as u8, 8, 252]),
            },
            water: Some(vec![80, 81]),
            views: strata_level::io::fostral_views(),
            edit: Some(EditSite::fostral()),
            source: Default::default(),
        };
        write_world(&dir, &world).unwrap();
        let back = load_world(&dir, MidRule::Original).unwrap();
        assert_eq!(back.name, "world_round_trip");
        assert!(back.level == world.level);
        assert_eq!(back.palette, world.palette);
        assert_eq!(back.water, world.water);
        assert_eq!(back.views, world.views);
        assert_eq!(back.edit, world.edit);
        assert_eq!(back.config.compressed, compressed);
        assert!(
            dir.join(if compressed { "mine.vmc" } else { "mine.vmp" })
                .exists()
        );
    }
    // The mid rule is the loader's option.
    let vange = load_world(&dir, MidRule::VangeRs).unwrap();
    assert_eq!(vange.level.mid_rule, MidRule::VangeRs);
}

#[test]
fn fostral_directory_without_map_names_the_missing_file() {
    let dir = temp_dir("fostral_copy");
    let src = common::fostral_dir();
    for f in ["world.ini", "harmony.pal", "output.vpr"] {
        std::fs::copy(src.join(f), dir.join(f)).unwrap();
    }
    let e = strata_level::io::load_world(&dir, MidRule::Original).unwrap_err();
    assert!(e.to_string().contains("output.vmc"), "{e}");
    // With a (synthetic) map of Fostral's size the paper's views and crater apply.
    let level = synthetic(2048, 16384, 12);
    std::fs::write(
        dir.join("output.vmc"),
        encode_vmc(&level, Path::new(P)).unwrap(),
    )
    .unwrap();
    let world = strata_level::io::load_world(&dir, MidRule::Original).unwrap();
    assert_eq!(world.views.len(), 12);
    assert_eq!(world.views[1].name, "hangar");
    assert_eq!(world.edit, Some(strata_level::EditSite::fostral()));
    assert_eq!(world.water.as_deref().map(|w| w.len()), Some(128));
    assert!(world.level == level);
}

#[test]
fn world_directory_errors_name_the_file() {
    use strata_level::io::{load_world, write_world};
    use strata_level::{World, WorldConfig};
    let dir = temp_dir("world_errors");
    let world = World {
        name: "x".into(),
        level: synthetic(64, 32, 13),
        config: WorldConfig {
            map_power_x: 6,
            map_power_y: 5,
            ..WorldConfig::default()
        },
        palette: strata_level::Palette {
            colors: [[4, 8, 12]; 256],
        },
        water: None,
        views: Vec::new(),
        edit: None,
        source: Default::default(),
    };
    write_world(&dir, &world).unwrap();
    assert!(!dir.join("views.txt").exists() && !dir.join("output.vpr").exists());
    let back = load_world(&dir, MidRule::Original).unwrap();
    assert!(back.views.is_empty() && back.edit.is_none() && back.water.is_none());

    let load_err = || load_world(&dir, MidRule::Original).unwrap_err().to_string();
    std::fs::write(dir.join("views.txt"), "river 1,2:3 0\n").unwrap();
    let e = load_err();
    assert!(e.contains("views.txt") && e.contains("line 1"), "{e}");
    std::fs::remove_file(dir.join("views.txt")).unwrap();

    std::fs::write(dir.join("output.vpr"), [0u8; 3]).unwrap();
    let e = load_err();
    assert!(e.contains("output.vpr") && e.contains("too short"), "{e}");
    std::fs::remove_file(dir.join("output.vpr")).unwrap();

    std::fs::write(dir.join("harmony.pal"), [0u8; 10]).unwrap();
    let e = load_err();
    assert!(e.contains("harmony.pal") && e.contains("10 bytes"), "{e}");

    let ini = std::fs::read_to_string(dir.join("world.ini")).unwrap();
    std::fs::write(
        dir.join("world.ini"),
        ini.replace("Map Power Y=5", "Map Power Y=6"),
    )
    .unwrap();
    let e = load_err();
    assert!(e.contains("output.vmc"), "{e}");
    std::fs::remove_file(dir.join("world.ini")).unwrap();
    let e = load_err();
    assert!(e.contains("world.ini"), "{e}");

    // Writing refuses a config whose size disagrees with the level.
    let mut bad = world.clone();
    bad.config.map_power_x = 7;
    let e = write_world(&dir, &bad).unwrap_err().to_string();
    assert!(e.contains("world.ini") && e.contains("disagrees"), "{e}");
}
