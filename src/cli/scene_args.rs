//! The scene options `fit` and `render` share: which camera and water, the water's optics
//! (the gloss stays with each command: `fit` also takes "auto"), and the light units.

use streaklight::optics::Shadowing;
use streaklight::scene_in::LoadOptions;

/// Scene options shared by `fit` and `render`.
#[derive(clap::Args)]
pub struct SceneArgs {
    /// Camera node or camera name (default: the first camera of the default scene).
    #[arg(long)]
    pub camera: Option<String>,
    /// Water node or mesh name (default: the one mesh node whose name contains "water").
    #[arg(long)]
    pub water: Option<String>,
    /// Index of refraction of the water, above 1 (dimensionless; water 1.33, sea water 1.34;
    /// default: its material's KHR_materials_ior, else 1.33).
    #[arg(long, value_name = "N", value_parser = super::values::ior)]
    pub ior: Option<f32>,
    /// Light intensity units per unit of radiance, > 0: 1 keeps the photo's units, 683 (lm/W)
    /// turns W/(sr m^2) into cd/m^2 (nits).
    #[arg(long, value_name = "SCALE", default_value_t = 1.0, value_parser = super::values::positive_f64)]
    pub nits_scale: f64,
    /// Use Smith shadowing in the reflection model (default: the paper's G = 1).
    #[arg(long)]
    pub smith: bool,
}

impl SceneArgs {
    /// How to load the scene, with the water's gloss `gloss` (`None`: its material's).
    pub fn load_options(&self, gloss: Option<f32>) -> LoadOptions {
        LoadOptions {
            camera: self.camera.clone(),
            water: self.water.clone(),
            gloss,
            ior: self.ior,
            nits_scale: self.nits_scale,
        }
    }

    /// The reflection model's shadowing term.
    pub fn shadowing(&self) -> Shadowing {
        if self.smith {
            Shadowing::Smith
        } else {
            Shadowing::None
        }
    }
}
