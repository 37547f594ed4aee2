//! The example's scene, headless, in every method: where the vehicle is
//! under the slab the picture is the terrain's alone (not one vehicle
//! pixel); where it is in the open or in the crater dug at start its centre
//! pixel shows the vehicle. The window draws the same `Drive`.

use strata_example_drive::{Drive, HEADLESS_COLOR, Offscreen, open_gpu, scene, vehicle};

const SIZE: (u32, u32) = (160, 100);

fn vehicle_pixels(rgba: &[u8]) -> usize {
    rgba.chunks_exact(4)
        .filter(|p| vehicle::is_vehicle_pixel([p[0], p[1], p[2]]))
        .count()
}

#[test]
fn vehicle_hides_under_the_slab_and_shows_in_the_open_in_every_method() {
    let gpu = match open_gpu(strata_render::AdapterChoice::default().instance(), None) {
        Ok(gpu) => gpu,
        Err(e) => {
            if std::env::var_os("STRATA_REQUIRE_GPU").is_some_and(|v| v == "1") {
                panic!("STRATA_REQUIRE_GPU=1 but {e:#}");
            }
            eprintln!("\n*** SKIPPED drive occlusion test: {e:#} ***\n");
            return;
        }
    };
    let targets = Offscreen::new(&gpu.device, SIZE);
    let under_slab = scene::t_at(116.0);
    let in_open = scene::t_at(150.0);
    let in_crater = scene::t_at(scene::CRATER.0 as f32);
    let mut tested = 0;
    for name in strata_render::methods::names() {
        let mut drive = match Drive::with_shadows(&gpu, name, HEADLESS_COLOR, SIZE, false) {
            Ok(d) => d,
            Err(e) => {
                eprintln!("{name}: not on this adapter ({e:#})");
                continue;
            }
        };
        let camera = drive.camera;
        let mut frame = |t: Option<f32>| {
            let centre = drive
                .draw(t, &targets.color_view, None, &targets.depth_view)
                .unwrap();
            (centre, targets.read_rgba(&gpu).unwrap())
        };
        let (_, terrain) = frame(None);
        assert_eq!(vehicle_pixels(&terrain), 0, "{name}: terrain alone");

        // Under the slab: on the cave floor, below the ceiling, unseen.
        let (centre, hidden) = frame(Some(under_slab));
        let centre = centre.unwrap();
        assert!(
            centre.z < 70.0,
            "{name}: vehicle at {centre} is not under the ceiling"
        );
        let differing = terrain
            .chunks_exact(4)
            .zip(hidden.chunks_exact(4))
            .filter(|(a, b)| a != b)
            .count();
        println!(
            "{name}: under the slab at {centre}: {} vehicle pixels, {differing} pixels differ from the terrain alone",
            vehicle_pixels(&hidden)
        );
        assert_eq!(
            vehicle_pixels(&hidden),
            0,
            "{name}: vehicle seen through the slab"
        );
        assert_eq!(differing, 0, "{name}: the slab's pixels changed");

        // In the open and in the crater: its centre pixel is the vehicle's.
        for (what, t) in [("in the open", in_open), ("in the crater", in_crater)] {
            let (centre, seen) = frame(Some(t));
            let centre = centre.unwrap();
            let p = camera.project(centre).expect("on screen");
            let k = ((p.y as u32 * SIZE.0 + p.x as u32) * 4) as usize;
            let px = [seen[k], seen[k + 1], seen[k + 2]];
            println!(
                "{name}: {what} at {centre}: centre pixel {px:?}, {} vehicle pixels",
                vehicle_pixels(&seen)
            );
            assert!(
                vehicle::is_vehicle_pixel(px),
                "{name}: {what}: centre pixel {px:?}"
            );
            assert!(vehicle_pixels(&seen) >= 20, "{name}: {what}");
        }
        // The collider saw the crater dug at start.
        let centre = drive.vehicle_centre(in_crater);
        assert!(
            centre.z < f32::from(scene::GROUND),
            "{name}: vehicle at {centre} is not down in the crater"
        );
        tested += 1;
    }
    assert!(tested >= 2, "{tested} methods ran");
}
