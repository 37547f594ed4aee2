//! Export round trips: the GLB read back with the gltf crate; OBJ counts;
//! region errors.

use strata_export::{ExportError, Format, Region, TerrainSoup};
use strata_level::World;
use strata_level::generate::{GenerateParams, generate};

fn world() -> World {
    generate(&GenerateParams {
        width: 256,
        height: 256,
        ..Default::default()
    })
    .expect("a small generated world")
}

/// `.gltf` is JSON (not GLB bytes), a valid glTF document whose one buffer
/// is embedded as a base64 data URI holding the same bytes as the GLB's
/// binary chunk.
#[test]
fn gltf_json_embeds_the_glb_buffer() {
    use base64::Engine as _;
    let world = world();
    let region = Region::parse("0,0,96,96", &world.level).unwrap();
    let soup = TerrainSoup::build(&world, region, 0.5).unwrap();
    let (mut json, mut glb) = (Vec::new(), Vec::new());
    soup.write(Format::Gltf, &mut json).unwrap();
    soup.write(Format::Glb, &mut glb).unwrap();
    assert_eq!(json[0], b'{', "a .gltf file starts as JSON");
    let doc = gltf::Gltf::from_slice(&json).expect("a valid glTF JSON document");
    assert!(doc.blob.is_none());
    let buffer = doc.buffers().next().unwrap();
    let gltf::buffer::Source::Uri(uri) = buffer.source() else {
        panic!("the buffer must be embedded");
    };
    let b64 = uri
        .strip_prefix("data:application/octet-stream;base64,")
        .expect("a base64 data URI");
    let bin = base64::engine::general_purpose::STANDARD
        .decode(b64)
        .unwrap();
    assert_eq!(bin.len(), buffer.length());
    let glb = gltf::Gltf::from_slice(&glb).unwrap();
    assert_eq!(&glb.blob.as_deref().unwrap()[..bin.len()], &bin[..]);
    assert_eq!(
        Format::from_extension("t.GLTF".as_ref()),
        Some(Format::Gltf)
    );
    assert_eq!(Format::from_extension("t.glb".as_ref()), Some(Format::Glb));
    assert_eq!(Format::from_extension("t.png".as_ref()), None);
}

#[test]
fn glb_reads_back_with_counts_bounds_and_colours() {
    let world = world();
    let region = Region::parse("10,20,200,150", &world.level).unwrap();
    let soup = TerrainSoup::build(&world, region, 0.5).unwrap();
    let mut bytes = Vec::new();
    soup.write(Format::Glb, &mut bytes).unwrap();
    let glb = gltf::Gltf::from_slice(&bytes).expect("a valid GLB");
    let blob = glb.blob.as_deref().expect("the binary chunk");
    let prim = glb.meshes().next().unwrap().primitives().next().unwrap();
    let reader = prim.reader(|b| (b.index() == 0).then_some(blob));
    let positions: Vec<[f32; 3]> = reader.read_positions().unwrap().collect();
    let indices: Vec<u32> = reader.read_indices().unwrap().into_u32().collect();
    let colors: Vec<[u8; 4]> = reader.read_colors(0).unwrap().into_rgba_u8().collect();
    assert_eq!(positions.len(), soup.positions.len());
    assert_eq!(colors.len(), positions.len());
    assert_eq!(indices.len(), soup.triangles.len() * 3);
    assert!(indices.iter().all(|&i| (i as usize) < positions.len()));
    // Bounds: y-up, so x in the region (triangles whose centre lies inside
    // reach at most one chunk-triangle beyond), altitude in 0..=255, and
    // -y within the region's rows likewise.
    let bb = prim.bounding_box();
    println!(
        "glb {} bytes, {} vertices, {} triangles, bounds {bb:?}",
        bytes.len(),
        positions.len(),
        indices.len() / 3
    );
    assert!(bb.min[0] >= 10.0 - 128.0 && bb.max[0] <= 200.0 + 128.0);
    assert!(bb.min[1] >= 0.0 && bb.max[1] <= 255.0 && bb.max[1] > bb.min[1] + 10.0);
    assert!(-bb.max[2] >= 20.0 - 128.0 && -bb.min[2] <= 150.0 + 128.0);
    for p in &positions {
        assert!(
            p.iter()
                .zip(bb.min.iter().zip(&bb.max))
                .all(|(v, (lo, hi))| v >= lo && v <= hi)
        );
    }
    // Each triangle's centroid lies in the region.
    for t in indices.chunks(3) {
        let c = t.iter().fold([0.0f32; 3], |a, &i| {
            let p = positions[i as usize];
            [a[0] + p[0] / 3.0, a[1] + p[1] / 3.0, a[2] + p[2] / 3.0]
        });
        assert!(region.contains(f64::from(c[0]), f64::from(-c[2])), "{c:?}");
    }
    // More than one terrain colour, none transparent.
    let mut distinct: Vec<[u8; 4]> = colors.clone();
    distinct.sort_unstable();
    distinct.dedup();
    assert!(
        distinct.len() >= 2 && colors.iter().all(|c| c[3] == 255),
        "{distinct:?}"
    );
}

#[test]
fn a_region_across_the_wrap_is_one_piece() {
    let world = world();
    let region = Region::parse("200,0,300,64", &world.level).unwrap();
    let soup = TerrainSoup::build(&world, region, 0.5).unwrap();
    let (lo, hi) = soup.bounds();
    // Unwrapped: x runs on past 256 rather than jumping back to 0.
    assert!(
        lo[0] >= 200.0 - 128.0 && hi[0] > 256.0 && hi[0] <= 300.0 + 128.0,
        "{lo:?} {hi:?}"
    );
}

#[test]
fn obj_has_one_line_per_vertex_and_face() {
    let world = world();
    let soup = TerrainSoup::build(
        &world,
        Region::parse("0,0,64,64", &world.level).unwrap(),
        0.5,
    )
    .unwrap();
    let mut bytes = Vec::new();
    soup.write(Format::Obj, &mut bytes).unwrap();
    let text = String::from_utf8(bytes).unwrap();
    let v = text.lines().filter(|l| l.starts_with("v ")).count();
    let f = text.lines().filter(|l| l.starts_with("f ")).count();
    assert_eq!((v, f), (soup.positions.len(), soup.triangles.len()));
    assert!(
        text.lines()
            .find(|l| l.starts_with("v "))
            .unwrap()
            .split(' ')
            .count()
            == 7
    );
}

#[test]
fn bad_regions_and_quality_are_named() {
    let world = world();
    let level = &world.level;
    for (text, expect) in [
        ("1,2,3", "expected X0,Y0,X1,Y1"),
        ("a,b,c,d", "expected X0,Y0,X1,Y1"),
        ("10,10,5,20", "empty"),
        ("-5,0,10,10", "outside the map"),
        ("300,0,310,10", "outside the map"),
        ("0,0,300,10", "wider or taller"),
    ] {
        let err = Region::parse(text, level).unwrap_err().to_string();
        assert!(err.contains(expect) && err.contains(text), "{text}: {err}");
    }
    let err = TerrainSoup::build(&world, Region::whole(level), 1.5)
        .err()
        .unwrap();
    assert!(matches!(err, ExportError::Quality(q) if q == 1.5));
}

/// A region exported from a store through its chunk cache (only the
/// chunks under it read, within a small budget) equals the in-memory
/// export, across the map's wrapping corner too.
#[test]
fn a_region_read_from_a_store_equals_the_in_memory_export() {
    use std::sync::Arc;
    use strata_level::MidRule;
    use strata_store::{ChunkCache, DirStore, Layout};
    let world = generate(&GenerateParams {
        width: 512,
        height: 512,
        ..Default::default()
    })
    .unwrap();
    let dir = std::env::temp_dir().join(format!("strata-export-store-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let layout = Layout {
        chunk_height: 64,
        chunk_width: 64,
        gzip_level: 1,
    };
    let store = DirStore::create(&dir, &world, &layout).unwrap();
    let budget = 6 * 2 * 64 * 64;
    let cache = ChunkCache::new(Arc::clone(store.store()), budget, MidRule::Original);
    let shell = store.store().world_shell().unwrap();
    for text in ["10,20,200,150", "450,470,600,530", "0,0,512,512"] {
        let region = Region::parse_in(text, 512, 512).unwrap();
        let want = TerrainSoup::build(&world, region, 0.5).unwrap();
        let got = TerrainSoup::build_from(&cache, &shell, region, 0.5).unwrap();
        assert_eq!(got.positions, want.positions, "{text}");
        assert_eq!(got.colors, want.colors, "{text}");
        assert_eq!(got.triangles, want.triangles, "{text}");
        let st = cache.stats();
        assert!(st.peak_bytes <= budget, "{st:?}");
    }
    let _ = std::fs::remove_dir_all(&dir);
}
