//! The paper's sample scenes over a finer or coarser water mesh of the same ripples: for
//! measuring how the costs of a fit grow with the mesh (the speed bench's cost table).

use std::path::{Path, PathBuf};

use super::gltf_doc::{self, WaterBuffer};
use super::water_surface::{self, GridSpec};
use super::{catalogue, ripples, scene_parts, water_grid, SampleWater, Setup, WATER_BIN};
use crate::output_file::write_atomically;
use crate::{Error, Result};

/// The samples' water grid with `factor` times as many rows and as many columns (a mesh of
/// `factor`^2 times the triangles over the same extent).
pub fn finer_water_grid(factor: usize) -> GridSpec {
    let grid = water_grid();
    GridSpec {
        rows: grid.rows * factor,
        columns: grid.columns * factor,
        ..grid
    }
}

/// Writes the sample scenes named in `files` (for example `scene.gltf` and
/// `table1-truth.gltf`) into `dir`, with the photos' ripples meshed on `grid` in `water.bin`;
/// returns the files written. Only scenes of the paper's setup over the photos' own waves
/// can be written so; any other name is refused.
pub fn write_paper_scenes_on_grid(
    dir: &Path,
    files: &[&str],
    grid: &GridSpec,
) -> Result<Vec<PathBuf>> {
    let specs: Vec<_> = catalogue()
        .into_iter()
        .filter(|s| files.contains(&s.file.as_str()))
        .collect();
    if let Some(missing) = files.iter().find(|f| {
        !specs
            .iter()
            .any(|s| s.file == **f && s.setup == Setup::Paper && s.water == SampleWater::Waves)
    }) {
        return Err(Error::Usage(format!(
            "{missing} is not a sample scene of the paper's setup over the photos' waves"
        )));
    }
    crate::output_file::create_dir_all(dir)?;
    let buffer = WaterBuffer::new(&water_surface::mesh(&ripples(), grid));
    let bin = dir.join(WATER_BIN);
    write_atomically(&bin, &buffer.bytes)?;
    let mut written = vec![bin];
    for spec in &specs {
        let path = dir.join(&spec.file);
        let parts = scene_parts(spec, std::slice::from_ref(&buffer), &[]);
        let text = serde_json::to_string_pretty(&gltf_doc::scene_json(&parts))
            .map_err(|e| Error::output(&path, e.to_string()))?;
        write_atomically(&path, text.as_bytes())?;
        written.push(path);
    }
    Ok(written)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_water_has_two_triangles_per_grid_cell() {
        let dir =
            std::env::temp_dir().join(format!("streaklight-mesh-size-{}", std::process::id()));
        let grid = GridSpec {
            rows: 30,
            columns: 50,
            ..water_grid()
        };
        let written = write_paper_scenes_on_grid(&dir, &["scene.gltf", "table1-truth.gltf"], &grid)
            .expect("writing");
        assert_eq!(written.len(), 3);
        let plain = crate::scene_in::load(&dir.join("scene.gltf"), &Default::default())
            .expect("loading scene.gltf");
        let truth = crate::scene_in::load(&dir.join("table1-truth.gltf"), &Default::default())
            .expect("loading table1-truth.gltf");
        let _ = std::fs::remove_dir_all(&dir);
        // The water's 30 x 50 cells, two triangles each, and the wall's two.
        assert_eq!(plain.triangles.len(), 2 * 30 * 50 + 2);
        assert_eq!(truth.triangles.len(), 2 * 30 * 50 + 2);
        assert_eq!(plain.area_lights.len(), 0);
        assert_eq!(truth.area_lights.len(), 1);
    }

    #[test]
    fn finer_grids_multiply_rows_and_columns() {
        let (one, four) = (water_grid(), finer_water_grid(4));
        assert_eq!((four.rows, four.columns), (one.rows * 4, one.columns * 4));
        assert_eq!((four.near, four.far), (one.near, one.far));
    }

    #[test]
    fn other_setups_are_refused() {
        let dir = std::env::temp_dir().join("streaklight-mesh-size-refused");
        for file in ["scene-other-waves.gltf", "harbour.gltf", "no-such.gltf"] {
            let err = write_paper_scenes_on_grid(&dir, &[file], &water_grid())
                .expect_err("a scene that is not the paper's over its waves");
            assert!(err.to_string().contains(file), "{err}");
        }
        assert!(!dir.exists());
    }
}
