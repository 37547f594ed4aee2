//! A world read from files and written back keeps every byte it did not
//! change: `world.ini` line for line, the `.vpr`'s generator state, the
//! `.vmc`'s trees and unedited rows. And what Strata writes has the sizes
//! the game's readers require.

mod common;

use common::{fostral_dir, synthetic, temp_dir};
use std::path::Path;
use strata_level::edit::{EditRect, fill_single};
use strata_level::io::{load_world, write_world};
use strata_level::model::MidRule;
use strata_level::vmc::{VmcReuse, decode_vmc, encode_vmc, encode_vmc_reusing};
use strata_level::vpr::VprLayout;
use strata_level::{Level, WorldConfig};

fn read(path: &Path) -> Vec<u8> {
    std::fs::read(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// `(offset, size)` of row `y` in `.vmc` bytes.
fn row_bytes(vmc: &[u8], y: usize) -> &[u8] {
    let e = &vmc[y * 6..y * 6 + 6];
    let offset = i32::from_le_bytes([e[0], e[1], e[2], e[3]]) as usize;
    let size = i16::from_le_bytes([e[4], e[5]]) as usize;
    &vmc[offset..offset + size]
}

/// Fostral's own `world.ini`, palette and `.vpr`, with a synthetic map of
/// Fostral's size (the real one is not available here).
fn fostral_like_dir(name: &str) -> (std::path::PathBuf, Vec<u8>) {
    let dir = temp_dir(name);
    for f in ["world.ini", "harmony.pal", "output.vpr"] {
        std::fs::copy(fostral_dir().join(f), dir.join(f)).unwrap();
    }
    let vmc = encode_vmc(&synthetic(2048, 16384, 21), Path::new("output.vmc")).unwrap();
    std::fs::write(dir.join("output.vmc"), &vmc).unwrap();
    (dir, vmc)
}

#[test]
fn fostral_read_and_written_back_is_byte_identical_and_an_edit_changes_only_its_rows() {
    let (src, vmc) = fostral_like_dir("fostral_src");
    let world = load_world(&src, MidRule::Original).unwrap();
    let out = temp_dir("fostral_out");
    write_world(&out, &world).unwrap();
    for f in ["world.ini", "harmony.pal", "output.vpr", "output.vmc"] {
        assert!(
            read(&src.join(f)) == read(&out.join(f)),
            "{f} changed on write-back"
        );
    }

    // Dig a hole in rows 100..104 with heights and terrain the map already
    // uses, and raise one section's water.
    let mut edited = world.clone();
    let rect = EditRect {
        x: 300,
        y: 100,
        width: 40,
        height: 4,
    };
    fill_single(&mut edited.level, rect, 2, 1);
    edited.water.as_mut().unwrap()[5] = 95;
    let out2 = temp_dir("fostral_edited");
    write_world(&out2, &edited).unwrap();
    assert!(read(&src.join("world.ini")) == read(&out2.join("world.ini")));
    let (vpr_src, vpr_out) = (
        read(&src.join("output.vpr")),
        read(&out2.join("output.vpr")),
    );
    let differ: Vec<usize> = (0..vpr_src.len())
        .filter(|&i| vpr_src[i] != vpr_out[i])
        .collect();
    let level_5 = VprLayout::of(&world.config).flood_offset() as usize + 5 * 4;
    assert_eq!(differ, vec![level_5], "only section 5's level byte changes");
    let vmc_out = read(&out2.join("output.vmc"));
    let (reuse_bytes, reuse) =
        encode_vmc_reusing(&edited.level, &vmc, Path::new("output.vmc")).unwrap();
    assert!(reuse_bytes == vmc_out);
    assert_eq!(reuse, VmcReuse::Rows { changed: 4 });
    // Same trees, and every row outside 100..104 keeps its bytes.
    let trees = 16384 * 6..16384 * 6 + 4096;
    assert!(vmc[trees.clone()] == vmc_out[trees]);
    for y in (0..16384).filter(|y| !(100..104).contains(y)) {
        assert!(row_bytes(&vmc, y) == row_bytes(&vmc_out, y), "row {y}");
    }
    let back = load_world(&out2, MidRule::Original).unwrap();
    assert!(back.level == edited.level);
    assert_eq!(back.water, edited.water);
}

#[test]
fn an_edit_the_trees_cannot_encode_re_encodes_the_map() {
    // A flat map's trees know only the symbols of a flat map.
    let flat = Level::flat(64, 32, 10, 2).unwrap();
    let source = encode_vmc(&flat, Path::new("f.vmc")).unwrap();
    assert_eq!(
        encode_vmc_reusing(&flat, &source, Path::new("f.vmc")).unwrap(),
        (source.clone(), VmcReuse::Whole)
    );
    let mut edited = flat.clone();
    let rect = EditRect {
        x: 8,
        y: 3,
        width: 5,
        height: 2,
    };
    fill_single(&mut edited, rect, 200, 5);
    let (bytes, reuse) = encode_vmc_reusing(&edited, &source, Path::new("f.vmc")).unwrap();
    assert_eq!(reuse, VmcReuse::Fresh);
    let back = decode_vmc(&bytes, 64, 32, MidRule::Original, Path::new("f.vmc")).unwrap();
    assert!(back == edited);
    // A source that does not fit the map is no source at all.
    let other = encode_vmc(&Level::flat(64, 64, 10, 2).unwrap(), Path::new("o.vmc")).unwrap();
    let (_, reuse) = encode_vmc_reusing(&edited, &other, Path::new("f.vmc")).unwrap();
    assert_eq!(reuse, VmcReuse::Fresh);
}

#[test]
fn world_ini_keeps_comments_order_spacing_and_line_endings() {
    let text = "; made by hand\r\n[Global Parameters]\r\nMap Power X = 6\r\nMap Power Y=5\r\n\
        GeoNet Power=5\r\nSection Size Power=5\r\nMinimal Square Power=4\r\n\r\n\
        # storage\r\n[Storage]\r\nVersion=1.4\r\nCompressed Format Using=1\r\nFile Name=w\r\n\
        Palette File=w.pal\r\nExtra=kept\r\n\r\n[Rendering Parameters]\r\n\
        Begin Colors=   1 32 64 72  88 104 112 120\r\nEnd Colors=31 63 71 87 103 111 119 127\r\n\
        ; trailing comment, no newline";
    let path = Path::new("world.ini");
    let config = WorldConfig::parse(text, path).unwrap();
    assert_eq!(config.to_ini_text(), text);
    // A changed value rewrites its own line only, keeping the key as written.
    let mut changed = config.clone();
    changed.map_power_x = 7;
    changed.file_name = "v".into();
    let expected = text
        .replace("Map Power X = 6", "Map Power X =7")
        .replace("File Name=w\r\n", "File Name=v\r\n");
    assert_eq!(changed.to_ini_text(), expected);

    // Bytes that are not UTF-8 (a DOS-era comment) come back unchanged.
    let mut bytes = b"; \xc8\xe3\xf0\xe0\n".to_vec();
    bytes.extend_from_slice(text.replace("\r\n", "\n").as_bytes());
    let latin = WorldConfig::parse_bytes(&bytes, path).unwrap();
    assert_eq!(latin.file_name, "w");
    assert_eq!(latin.to_ini_bytes(), bytes);
}

#[test]
fn a_key_the_file_lacks_is_added_to_its_section() {
    use strata_level::config::Ini;
    let text = "[Storage]\nVersion=1.4\n; note\n\n[Rendering Parameters]\nEnd Colors=1";
    let mut ini = Ini::parse(text).unwrap();
    ini.set("Storage", "File Name", "w".into());
    ini.set("Rendering Parameters", "Begin Colors", "0".into());
    ini.set("Dynamic Palette", "Wave Terrain", "0".into());
    assert_eq!(
        ini.to_text(),
        "[Storage]\nVersion=1.4\nFile Name=w\n; note\n\n[Rendering Parameters]\nEnd Colors=1\n\
         Begin Colors=0\n\n[Dynamic Palette]\nWave Terrain=0\n"
    );
    assert_eq!(ini.get("Storage", "File Name"), Some("w"));
}

#[test]
fn generated_world_files_have_the_sizes_the_game_reads() {
    let world = strata_level::generate::generate(&strata_level::generate::GenerateParams {
        seed: 5,
        width: 256,
        height: 1024,
    })
    .unwrap();
    let dir = temp_dir("generated_sizes");
    write_world(&dir, &world).unwrap();
    // vange-rs's and the game's formula, written out for 256x1024, geo 5, sections of 128 rows.
    let (net, geo, sections) = ((256 * 1024) >> 10, 5, 1024 >> 7);
    let flood_offset = 2 * 4 + (1 + 4 + 4) * 4 + 2 * net + 2 * geo * 4 + 2 * sections * geo * 4;
    let vpr = read(&dir.join("output.vpr"));
    assert_eq!(vpr.len(), flood_offset + 4 * sections);
    assert!(vpr[..flood_offset].iter().all(|&b| b == 0));
    let level = i32::from_le_bytes(vpr[flood_offset..flood_offset + 4].try_into().unwrap());
    assert_eq!(level, strata_level::generate::SEA);
    // Palette: 768 bytes of 6-bit values.
    let pal = read(&dir.join(&world.config.palette_file));
    assert!(pal.len() == 768 && pal.iter().all(|&v| v < 64));
    // world.ini: every key the game and vange-rs require.
    let ini = WorldConfig::read(&dir.join("world.ini")).unwrap().ini;
    for (section, key) in [
        ("Global Parameters", "Map Power X"),
        ("Global Parameters", "Map Power Y"),
        ("Global Parameters", "GeoNet Power"),
        ("Global Parameters", "Section Size Power"),
        ("Global Parameters", "Minimal Square Power"),
        ("Storage", "Version"),
        ("Storage", "Compressed Format Using"),
        ("Storage", "File Name"),
        ("Storage", "Palette File"),
        ("Rendering Parameters", "Shadow Offsets"),
        ("Rendering Parameters", "Height Shifts"),
        ("Rendering Parameters", "Begin Colors"),
        ("Rendering Parameters", "End Colors"),
        ("Dynamic Palette", "Wave Terrain"),
        ("Dynamic Palette", "Terrain Number"),
    ] {
        assert!(ini.get(section, key).is_some(), "[{section}] {key}");
    }
    assert_eq!(ini.get("Storage", "Version"), Some("1.4"));
    // .vmc: the row table's rows follow the 6-byte entries and the two trees.
    let vmc = read(&dir.join("output.vmc"));
    let first = i32::from_le_bytes(vmc[..4].try_into().unwrap()) as usize;
    assert_eq!(first, 1024 * 6 + 2 * 512 * 4);
}

#[test]
fn vpr_missing_wrong_or_old() {
    let world = strata_level::generate::generate(&strata_level::generate::GenerateParams {
        seed: 5,
        width: 256,
        height: 512,
    })
    .unwrap();
    let dir = temp_dir("vpr_cases");
    write_world(&dir, &world).unwrap();
    let vpr = dir.join("output.vpr");
    let good = read(&vpr);
    let expected = VprLayout::of(&world.config).file_size();
    assert_eq!(good.len() as u64, expected);

    // Too short, and the wrong size for the map: both sizes and the file named.
    for len in [10usize, good.len() + 8] {
        let mut bad = good.clone();
        bad.resize(len, 0);
        std::fs::write(&vpr, &bad).unwrap();
        let e = load_world(&dir, MidRule::Original).unwrap_err().to_string();
        assert!(
            e.contains("output.vpr: ")
                && e.contains(&format!("{len} bytes"))
                && e.contains(&format!("{expected} bytes")),
            "{e}"
        );
    }

    // Strata's older layout still loads.
    let mut old = b"STRATVPR".to_vec();
    old.extend_from_slice(&4u32.to_le_bytes());
    old.extend_from_slice(&128u32.to_le_bytes());
    for l in [60i32, 61, 62, 63] {
        old.extend_from_slice(&l.to_le_bytes());
    }
    std::fs::write(&vpr, &old).unwrap();
    let back = load_world(&dir, MidRule::Original).unwrap();
    assert_eq!(back.water, Some(vec![60, 61, 62, 63]));
    // ...and is written back in the game's layout.
    let out = temp_dir("vpr_cases_out");
    write_world(&out, &back).unwrap();
    assert_eq!(read(&out.join("output.vpr")).len() as u64, expected);

    // Missing: water level 0 everywhere, and none written back.
    std::fs::remove_file(&vpr).unwrap();
    let back = load_world(&dir, MidRule::Original).unwrap();
    assert_eq!(back.water, None);
    assert_eq!(back.water_levels(), vec![0; 4]);
}
