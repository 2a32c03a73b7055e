//! A sample scene over another realisation of its waves: the same lights, camera and
//! surroundings over a water mesh drawn from another seed with the same statistics (the
//! harbour's spectrum, the paper's ripples). Photos rendered from such scenes show how far
//! one photo's waves move a fit under the statistical water model
//! (`benches/realisations.rs`, `tests/harbour_fit.rs`).

use std::path::{Path, PathBuf};

use super::gltf_doc::{self, WaterBuffer};
use super::harbour_waves::harbour_spectrum;
use super::water_surface::mesh;
use super::{catalogue, harbour, ripples_of, scene_parts, water_grid, SampleWater, Setup};
use crate::output_file::{create_dir_all, write_atomically};
use crate::{Error, Result};

/// Writes sample scene `file` (one of [`catalogue`] over its setup's waves, such as
/// `harbour-sign-truth.gltf`) into `dir`, its water mesh drawn from wave seed `seed`, with
/// the mesh's buffer beside it; returns the scene's path. Seeds 2018 (the paper's) and 2026
/// (the harbour's) give the photos' own waves.
pub fn write_over_waves(file: &str, seed: u64, dir: &Path) -> Result<PathBuf> {
    let spec = catalogue()
        .into_iter()
        .find(|s| s.file == file)
        .ok_or_else(|| Error::Usage(format!("no sample scene is named {file}")))?;
    if spec.water != SampleWater::Waves {
        return Err(Error::Usage(format!(
            "{file} is not set over its setup's waves: no realisation of them to replace"
        )));
    }
    let water = WaterBuffer::new(&match spec.setup {
        Setup::Paper => mesh(&ripples_of(seed), &water_grid()),
        Setup::Harbour(_) => harbour::water_mesh_of(&harbour_spectrum().realise(seed)),
    });
    let (paper, harbour) = match spec.setup {
        Setup::Paper => (std::slice::from_ref(&water), &[][..]),
        Setup::Harbour(_) => (&[][..], std::slice::from_ref(&water)),
    };
    let parts = scene_parts(&spec, paper, harbour);
    let gltf_doc::WaterGeometry::Mesh { uri, .. } = &parts.water else {
        return Err(Error::Usage(format!("{file} holds no water mesh")));
    };
    create_dir_all(dir)?;
    let path = dir.join(file);
    let text = serde_json::to_string_pretty(&gltf_doc::scene_json(&parts))
        .map_err(|e| Error::output(&path, e.to_string()))?;
    write_atomically(&dir.join(uri), &water.bytes)?;
    write_atomically(&path, text.as_bytes())?;
    Ok(path)
}
