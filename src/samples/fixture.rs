//! The unit tests' fixture: a sample scene loaded with a committed sample photo, its water
//! mask and its streaks, made once per test process and shared by the tests that only read
//! it (each making it afresh would write and load the sample scenes again, about 3 s apiece).

use std::collections::BTreeMap;
use std::path::Path;
use std::sync::{Mutex, OnceLock};

use super::{write_scenes, PHOTO_EXPOSURE};

/// The sample scene (`scene.gltf`), the committed sample photo at the samples' exposure, its
/// water mask and its streaks as the fitters take them.
pub(crate) struct Fixture {
    pub(crate) scene: crate::scene_in::Scene,
    pub(crate) photo: crate::photo_in::Photo,
    pub(crate) water: Vec<bool>,
    pub(crate) observations: Vec<crate::fitting::StreakObservation>,
}

/// The fixture of sample photo `photo`, made on the first call and shared after it: for tests
/// that read it (the scene's lazily built parts and caches give the same answers to every
/// reader). A test that changes the scene makes its own with [`load_fixture`].
pub(crate) fn fixture(photo: &str) -> &'static Fixture {
    static MADE: Mutex<BTreeMap<String, &'static OnceLock<Fixture>>> = Mutex::new(BTreeMap::new());
    let cell: &'static OnceLock<Fixture> = {
        let mut made = MADE.lock().unwrap_or_else(|poisoned| poisoned.into_inner());
        made.entry(photo.to_string())
            .or_insert_with(|| Box::leak(Box::new(OnceLock::new())))
    };
    // Made outside the map's lock: a test asking for another photo need not wait for it.
    cell.get_or_init(|| load_fixture(photo))
}

/// A fixture of its own for sample photo `photo` (see [`fixture`]): the sample scenes written
/// to a temporary folder, loaded, and the folder removed.
pub(crate) fn load_fixture(photo: &str) -> Fixture {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let dir = std::env::temp_dir().join(format!(
        "streaklight-fixture-{}-{:?}",
        std::process::id(),
        std::thread::current().id()
    ));
    write_scenes(&dir).expect("sample scenes");
    let scene = crate::scene_in::load(&dir.join("scene.gltf"), &Default::default()).expect("scene");
    let _ = std::fs::remove_dir_all(&dir);
    let photo =
        crate::photo_in::load(&root.join("samples").join(photo), PHOTO_EXPOSURE).expect("photo");
    let water = crate::water_mask::water_mask(&scene, photo.width, photo.height);
    let segmented =
        crate::streaks::extract_streaks(&photo, &water, &Default::default()).expect("streaks");
    let observations = segmented
        .streaks
        .iter()
        .map(|s| crate::pipeline::observation(s, photo.width))
        .collect();
    Fixture {
        scene,
        photo,
        water,
        observations,
    }
}
