//! What a run records besides its rows: the edit protocol's pictures and
//! the adapter.

use crate::edits;
use crate::plan::file_part;
use crate::results::{AdapterInfo, EditImages};
use crate::session::{Session, color_image};
use anyhow::Context;
use strata_camera::Camera;

/// Save the edit camera's before and first-post-edit pictures and record them.
pub(super) fn save_edit_pictures(
    session: &mut Session,
    camera: &Camera,
    label: &str,
    pictures: edits::EditPictures,
) -> anyhow::Result<()> {
    let save = |when: &str, rgba: Vec<u8>| -> anyhow::Result<String> {
        let rel = format!("cells/edit-{}-{when}.png", file_part(label));
        let path = session.out.join(&rel);
        color_image(camera.width, camera.height, rgba)?
            .save(&path)
            .with_context(|| format!("writing {}", path.display()))?;
        Ok(rel)
    };
    let before = save("before", pictures.before)?;
    let after = save("after", pictures.after)?;
    session.results.edit_images.push(EditImages {
        method: label.to_string(),
        before,
        after,
    });
    Ok(())
}

/// The results file's record of the adapter `gpu` runs on.
pub(crate) fn adapter_info(gpu: &strata_render::Gpu) -> AdapterInfo {
    AdapterInfo {
        name: gpu.report.name.clone(),
        backend: gpu.report.backend.clone(),
        driver: format!("{} {}", gpu.report.driver, gpu.report.driver_info)
            .trim()
            .to_string(),
        timestamps: gpu.report.timestamps,
    }
}
