//! Property tests: corrupted files give `Ok` or `Err`, never a panic.

mod common;

use proptest::prelude::*;
use std::path::Path;
use std::sync::OnceLock;
use strata_level::edit::{EditRect, fill_single};
use strata_level::model::MidRule;
use strata_level::vmc::{decode_vmc, encode_vmc};
use strata_level::{Palette, WorldConfig};

fn good_vmc() -> &'static Vec<u8> {
    static BYTES: OnceLock<Vec<u8>> = OnceLock::new();
    BYTES.get_or_init(|| encode_vmc(&common::synthetic(32, 16, 3), Path::new("x")).unwrap())
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(400))]

    #[test]
    fn corrupted_vmc_never_panics(
        flips in prop::collection::vec((any::<prop::sample::Index>(), any::<u8>()), 0..8),
        cut in any::<prop::sample::Index>(),
        truncate in any::<bool>(),
    ) {
        let mut bytes = good_vmc().clone();
        for (at, v) in flips {
            let i = at.index(bytes.len());
            bytes[i] = v;
        }
        if truncate {
            bytes.truncate(cut.index(bytes.len()));
        }
        let r = decode_vmc(&bytes, 32, 16, MidRule::Original, Path::new("f.vmc"));
        if let Err(e) = r {
            prop_assert!(e.to_string().starts_with("f.vmc: "));
        }
    }

    #[test]
    fn random_ini_text_never_panics(text in "(\\[[A-Za-z ]{0,12}\\]\n|[A-Za-z ]{0,12}=[0-9a-z ./-]{0,20}\n|[^\n]{0,20}\n){0,20}") {
        let _ = WorldConfig::parse(&text, Path::new("world.ini"));
    }

    #[test]
    fn ini_with_one_bad_value_never_panics(key in 0usize..7, value in "[0-9a-z ./-]{0,12}") {
        let keys = ["Map Power X", "Map Power Y", "Compressed Format Using", "File Name",
                    "Palette File", "Begin Colors", "End Colors"];
        let good = WorldConfig::default().to_ini_text();
        let bad: String = good
            .lines()
            .map(|l| if l.starts_with(keys[key]) { format!("{}={value}\n", keys[key]) } else { format!("{l}\n") })
            .collect();
        let _ = WorldConfig::parse(&bad, Path::new("world.ini"));
    }

    #[test]
    fn random_palettes_never_panic(bytes in prop::collection::vec(any::<u8>(), 0..800)) {
        let _ = Palette::from_bytes(&bytes, Path::new("p.pal"));
    }

    #[test]
    fn random_edit_rects_never_panic(x in any::<i64>(), y in any::<i64>(), w in any::<u32>(), h in 0u32..64, v in any::<u8>()) {
        let mut level = common::synthetic(16, 8, 1);
        let dirty = fill_single(&mut level, EditRect { x, y, width: w, height: h }, v, v);
        let area: u32 = dirty.iter().map(|r| r.width * r.height).sum();
        prop_assert!(area <= 16 * 8);
    }
}
