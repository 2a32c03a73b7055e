//! The harbour samples: a night photo as people take them from a quay.
//!
//! The camera stands 2 m above the water at (0, 2, 40), vertical fov 60 degrees, looking
//! down -z over harbour chop ([`super::harbour_waves`]) at a facade on the water at z = 0,
//! 40 m away, on which the lights hang (all at least 4 m above the water). Two framings:
//! pitched down 10 degrees, the lights are in the photo above their reflections
//! ([`Framing::InFrame`]); pitched down 28 degrees, the top of the photo is 2 degrees above
//! the horizon, below every light, while their reflections stay in it ([`Framing::Above`]).
//! The near quay the camera stands on (its top 0.4 m above the water, its face 0.8 m in
//! front of the camera) is just out of both framings.
//!
//! The water mesh is one grid for both framings, its rows at constant z and its columns
//! evenly spread over what either camera sees of each row (with a margin). Rows follow the
//! photo's pixel rows (one per row, 2 m / d^2 of the view's tangent) where that spacing is
//! between [`MIN_ROW_SPACING`] and [`MAX_ROW_SPACING`]; nearer they would be finer than the
//! shortest wave needs, farther too coarse for the waves, so the spacing is clamped. Each
//! wave is attenuated by a Gaussian of half the local spacing, which leaves the waves the
//! grid resolves almost whole and damps those it cannot carry.

use super::gltf_doc::{CameraPose, Quad, Solid};
use super::harbour_waves::harbour_spectrum;
use super::water_surface::{mesh_rows, GridRow, RippleField, WaterMesh};
use super::{SampleLight, SampleScene, SampleWater, Setup, PHOTO_SIZE};
use crate::environment::Environment;

/// The camera's position.
pub const HARBOUR_CAMERA: [f64; 3] = [0.0, 2.0, 40.0];
/// The camera's vertical field of view, in degrees.
pub const HARBOUR_YFOV_DEGREES: f64 = 60.0;
/// Gloss e of the water material of the scenes with waves (the micro-roughness below the
/// mesh's waves: slope variance 1 / (e + 2) per axis, rms 0.022).
pub const HARBOUR_GLOSS: f64 = 2000.0;
/// Seeds of the two wave realisations: the photos' waves and the other waves.
pub const HARBOUR_WAVE_SEEDS: [u64; 2] = [2026, 1202];
/// File name of the photos' water mesh.
pub const HARBOUR_WATER_BIN: &str = "harbour-water.bin";
/// File name of the other realisation's water mesh.
pub const HARBOUR_OTHER_WATER_BIN: &str = "harbour-water-other.bin";
/// Column intervals of the water grid.
pub const HARBOUR_COLUMNS: usize = 400;
/// Finest row spacing of the water grid (m): a fifth of the shortest wave.
pub const MIN_ROW_SPACING: f64 = 0.03;
/// Coarsest row spacing of the water grid (m).
pub const MAX_ROW_SPACING: f64 = 0.1;
/// Nearest water row: the face of the quay, this far in front of the camera (m).
const QUAY_EDGE: f64 = 0.8;
/// Height of the quay's top above the water (m).
const QUAY_TOP: f64 = 0.4;
/// Farthest water row, just behind the facade (m from the camera).
const WATER_FAR: f64 = 40.5;

/// How the harbour camera frames the lights.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Framing {
    /// Lights and reflections in the photo.
    InFrame,
    /// Lights above the top of the photo, their reflections in it.
    Above,
}

impl Framing {
    /// Both framings.
    pub const ALL: [Framing; 2] = [Framing::InFrame, Framing::Above];

    /// The camera's pitch down, in degrees.
    pub fn pitch_degrees(self) -> f64 {
        match self {
            Framing::InFrame => 10.0,
            Framing::Above => 28.0,
        }
    }

    /// What file names of this framing add after `harbour`.
    fn suffix(self) -> &'static str {
        match self {
            Framing::InFrame => "",
            Framing::Above => "-above",
        }
    }
}

/// The camera of `framing`.
pub fn camera(framing: Framing) -> CameraPose {
    CameraPose {
        name: "HarbourCamera".into(),
        translation: HARBOUR_CAMERA,
        pitch_degrees: framing.pitch_degrees(),
        yfov_degrees: HARBOUR_YFOV_DEGREES,
    }
}

/// The three layouts of truth lights on the facade: name, description, lights.
pub fn layouts() -> Vec<(&'static str, &'static str, Vec<SampleLight>)> {
    vec![
        (
            "pair",
            "an orange light (-9, 4.5, 0) 4 x 2 m L = (24, 12, 3) and a blue one (5, 5.5, 0) 3 x 1.5 m L = (4, 10, 24)",
            vec![
                SampleLight::new("orange", [-9.0, 4.5, 0.0], [4.0, 2.0], [24.0, 12.0, 3.0]),
                SampleLight::new("blue", [5.0, 5.5, 0.0], [3.0, 1.5], [4.0, 10.0, 24.0]),
            ],
        ),
        (
            "sign",
            "one warm white sign (-3, 6, 0) 6 x 1.2 m L = (20, 18, 14)",
            vec![SampleLight::new(
                "sign",
                [-3.0, 6.0, 0.0],
                [6.0, 1.2],
                [20.0, 18.0, 14.0],
            )],
        ),
        (
            "three",
            "three lights: green-white (-14, 4, 0) 1 x 3 m L = (8, 20, 12), warm (-2, 4.5, 0) 2 x 2 m L = (22, 16, 8), red (10, 7, 0) 2.5 x 1 m L = (24, 5, 4)",
            vec![
                SampleLight::new("tall", [-14.0, 4.0, 0.0], [1.0, 3.0], [8.0, 20.0, 12.0]),
                SampleLight::new("warm", [-2.0, 4.5, 0.0], [2.0, 2.0], [22.0, 16.0, 8.0]),
                SampleLight::new("red", [10.0, 7.0, 0.0], [2.5, 1.0], [24.0, 5.0, 4.0]),
            ],
        ),
    ]
}

/// The photos' waves (`realisation` 0) or the other waves (1).
pub fn harbour_waves(realisation: usize) -> RippleField {
    harbour_spectrum().realise(HARBOUR_WAVE_SEEDS[realisation.min(1)])
}

/// Half the width of the water either camera sees at distance `d` in front of it, with a
/// margin: a point (x, 0, z) is in a camera's view when |x| <= tan(fov / 2) times its depth
/// along the camera's axis, h sin(pitch) + d cos(pitch).
fn half_width(d: f64) -> f64 {
    let tan_half = (0.5 * HARBOUR_YFOV_DEGREES.to_radians()).tan();
    let h = HARBOUR_CAMERA[1];
    let depth = Framing::ALL
        .iter()
        .map(|f| {
            let p = f.pitch_degrees().to_radians();
            h * p.sin() + d * p.cos()
        })
        .fold(d, f64::max);
    1.05 * tan_half * depth + 0.5
}

/// The water grid's rows, near to far.
pub fn grid_rows() -> Vec<GridRow> {
    let h = HARBOUR_CAMERA[1];
    let focal = 0.5 * PHOTO_SIZE as f64 / (0.5 * HARBOUR_YFOV_DEGREES.to_radians()).tan();
    // A pixel row sees d^2 / (h f) of water along the view at distance d.
    let spacing = |d: f64| (d * d / (h * focal)).clamp(MIN_ROW_SPACING, MAX_ROW_SPACING);
    let mut rows = Vec::new();
    let mut d = QUAY_EDGE;
    loop {
        let dz = spacing(d);
        rows.push(GridRow {
            z: HARBOUR_CAMERA[2] - d,
            dz,
            half_width: half_width(d),
        });
        if d >= WATER_FAR {
            break;
        }
        d = (d + dz).min(WATER_FAR);
    }
    rows
}

/// The water mesh of wave realisation `realisation` (0: the photos', 1: the other).
pub fn water_mesh(realisation: usize) -> WaterMesh {
    water_mesh_of(&harbour_waves(realisation))
}

/// The harbour's water grid over the waves `field`.
pub fn water_mesh_of(field: &RippleField) -> WaterMesh {
    mesh_rows(field, &grid_rows(), HARBOUR_COLUMNS, 0.5)
}

/// The flat water: one quad over the grid's extent.
pub fn flat_water() -> Quad {
    Quad::level_water(
        (HARBOUR_CAMERA[2] - QUAY_EDGE) as f32,
        (HARBOUR_CAMERA[2] - WATER_FAR) as f32,
        half_width(WATER_FAR) as f32,
    )
}

/// The facade at z = 0 (facing the camera) and the near quay (its top and its face towards
/// the water).
pub fn solids() -> Vec<Solid> {
    let (x0, x1) = (-60.0f32, 60.0f32);
    let facade = Quad {
        corners: [
            [x0, -1.0, 0.0],
            [x1, -1.0, 0.0],
            [x1, 30.0, 0.0],
            [x0, 30.0, 0.0],
        ],
        normal: [0.0, 0.0, 1.0],
    };
    let edge = (HARBOUR_CAMERA[2] - QUAY_EDGE) as f32;
    let back = (HARBOUR_CAMERA[2] + 10.0) as f32;
    let top = QUAY_TOP as f32;
    let quay_top = Quad {
        corners: [
            [x0, top, back],
            [x1, top, back],
            [x1, top, edge],
            [x0, top, edge],
        ],
        normal: [0.0, 1.0, 0.0],
    };
    // Seen from -z (from the water), +x is to the left.
    let quay_face = Quad {
        corners: [
            [x1, -1.0, edge],
            [x0, -1.0, edge],
            [x0, top, edge],
            [x1, top, edge],
        ],
        normal: [0.0, 0.0, -1.0],
    };
    vec![
        Solid {
            name: "Facade".into(),
            quads: vec![facade],
        },
        Solid {
            name: "Quay".into(),
            quads: vec![quay_top, quay_face],
        },
    ]
}

/// The harbour entries of the catalogue: per framing, the scenes a fit takes (the photos'
/// own waves, the other waves, flat water; no lights), then one truth scene with its photo
/// per layout.
pub fn catalogue(flat_gloss: f64) -> Vec<SampleScene> {
    let mut scenes = Vec::new();
    for framing in Framing::ALL {
        let sfx = framing.suffix();
        let view = match framing {
            Framing::InFrame => "lights in frame",
            Framing::Above => "lights above the frame",
        };
        let scene = |file: String, description: String, water, gloss, lights, photo| SampleScene {
            file,
            description,
            wall_z: 0.0,
            gloss,
            lights,
            photo,
            photo_exr: None,
            setup: Setup::Harbour(framing),
            water,
            environment: None,
        };
        scenes.push(scene(
            format!("harbour{sfx}.gltf"),
            format!("the harbour, {view}, over the photos' own waves, without lights"),
            SampleWater::Waves,
            HARBOUR_GLOSS,
            vec![],
            None,
        ));
        scenes.push(scene(
            format!("harbour{sfx}-other-waves.gltf"),
            format!(
                "the harbour, {view}, over another realisation of the same waves, without lights"
            ),
            SampleWater::OtherWaves,
            HARBOUR_GLOSS,
            vec![],
            None,
        ));
        scenes.push(scene(
            format!("harbour{sfx}-flat.gltf"),
            format!("the harbour, {view}, over a flat quad whose roughness matches the waves' slopes, without lights"),
            SampleWater::Flat,
            flat_gloss,
            vec![],
            None,
        ));
        for (name, description, lights) in layouts() {
            scenes.push(scene(
                format!("harbour-{name}{sfx}-truth.gltf"),
                format!("the harbour, {view}: {description}"),
                SampleWater::Waves,
                HARBOUR_GLOSS,
                lights,
                Some(format!("harbour-{name}{sfx}.png")),
            ));
        }
        if framing == Framing::InFrame {
            let (_, description, lights) = &layouts()[0];
            scenes.push(SampleScene {
                environment: Some(NIGHT),
                ..scene(
                    "harbour-night-truth.gltf".into(),
                    format!(
                        "the harbour, {view}: {description}, under a dim sky (radiance {}) \
                         that lights the facades (albedo {})",
                        NIGHT.sky[0], NIGHT.albedo
                    ),
                    SampleWater::Waves,
                    HARBOUR_GLOSS,
                    lights.clone(),
                    Some("harbour-night.png".into()),
                )
            });
        }
    }
    scenes
}

/// The night of `harbour-night.png`: a grey sky 1/50 of the pair's lamps' brightest channel,
/// which lights the facades of albedo 0.25 to about 1/400 of the lamps; the water reflects
/// both.
pub const NIGHT: Environment = Environment {
    sky: [0.5; 3],
    albedo: 0.25,
};

#[cfg(test)]
mod tests {
    use super::*;

    /// The grid covers the water from the quay to behind the facade without gaps, its rows
    /// step by at most the coarsest spacing, and the mesh stays a few hundred thousand
    /// triangles.
    #[test]
    fn grid_spans_the_harbour() {
        let rows = grid_rows();
        let first = rows.first().map(|r| r.z).unwrap_or(f64::NAN);
        let last = rows.last().map(|r| r.z).unwrap_or(f64::NAN);
        assert!((first - (HARBOUR_CAMERA[2] - QUAY_EDGE)).abs() < 1e-9);
        assert!((last - (HARBOUR_CAMERA[2] - WATER_FAR)).abs() < 1e-9);
        for pair in rows.windows(2) {
            let step = pair[0].z - pair[1].z;
            assert!(step > 0.0 && step <= MAX_ROW_SPACING + 1e-12, "{step}");
        }
        let triangles = (rows.len() - 1) * HARBOUR_COLUMNS * 2;
        assert!((200_000..500_000).contains(&triangles), "{triangles}");
    }
}
