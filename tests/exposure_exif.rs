//! `--exposure auto`: the exposure from the photo's EXIF (exposure time t, f-number N, ISO
//! speed S) by the reflected-light meter equation, through the binary. The photos are the
//! fit tests' rendered PNG with EXIF written by the test: as a PNG eXIf chunk, and in a JPEG's
//! APP1 segment. The expected exposure is computed here from the equation, not by the
//! library: X = 0.18 * 683 * t * S / (12.5 * N^2).

mod common;

use std::io::Cursor;
use std::path::{Path, PathBuf};

use common::cli::run_cli_code as run;
use common::cli::{arg, SAMPLES_ARG};
use common::fit_case;
use common::json::read_json;
use exif::{Field, In, Rational, Tag, Value};

/// The camera settings written into a test photo: exposure time (numerator, denominator),
/// f-number (numerator, denominator), ISO speed; `None` leaves the tag out.
#[derive(Clone, Copy)]
struct Settings {
    time: Option<(u32, u32)>,
    f_number: Option<(u32, u32)>,
    iso: Option<u16>,
}

/// 1/60 s, f/8, ISO 100.
const A: Settings = Settings {
    time: Some((1, 60)),
    f_number: Some((8, 1)),
    iso: Some(100),
};
/// 1/30 s, f/2.8, ISO 800.
const B: Settings = Settings {
    time: Some((1, 30)),
    f_number: Some((28, 10)),
    iso: Some(800),
};

/// The exposure the meter equation gives: linear value per W/(sr m^2).
fn expected_exposure(s: Settings) -> f64 {
    let (tn, td) = s.time.unwrap();
    let (nn, nd) = s.f_number.unwrap();
    let t = f64::from(tn) / f64::from(td);
    let n = f64::from(nn) / f64::from(nd);
    let iso = f64::from(s.iso.unwrap());
    // L_m = K N^2 / (t S) cd/m^2 is recorded at 0.18; 683 cd/m^2 is 1 W/(sr m^2).
    let metered = 12.5 * n * n / (t * iso);
    0.18 * 683.0 / metered
}

/// The TIFF-structured EXIF of `s`.
fn exif_bytes(s: Settings) -> Vec<u8> {
    let rational = |(num, denom): (u32, u32)| Value::Rational(vec![Rational { num, denom }]);
    let mut fields = Vec::new();
    if let Some(t) = s.time {
        fields.push(Field {
            tag: Tag::ExposureTime,
            ifd_num: In::PRIMARY,
            value: rational(t),
        });
    }
    if let Some(n) = s.f_number {
        fields.push(Field {
            tag: Tag::FNumber,
            ifd_num: In::PRIMARY,
            value: rational(n),
        });
    }
    if let Some(iso) = s.iso {
        fields.push(Field {
            tag: Tag::PhotographicSensitivity,
            ifd_num: In::PRIMARY,
            value: Value::Short(vec![iso]),
        });
    }
    // A primary IFD needs one field of its own besides the EXIF pointer.
    let software = Field {
        tag: Tag::Software,
        ifd_num: In::PRIMARY,
        value: Value::Ascii(vec![b"streaklight test".to_vec()]),
    };
    let mut writer = exif::experimental::Writer::new();
    writer.push_field(&software);
    for f in &fields {
        writer.push_field(f);
    }
    let mut out = Cursor::new(Vec::new());
    writer.write(&mut out, false).unwrap();
    out.into_inner()
}

/// CRC-32 (ISO 3309, as PNG chunks use), bit by bit.
fn crc32(bytes: &[u8]) -> u32 {
    let mut crc = 0xffff_ffffu32;
    for &b in bytes {
        crc ^= u32::from(b);
        for _ in 0..8 {
            crc = if crc & 1 != 0 {
                (crc >> 1) ^ 0xedb8_8320
            } else {
                crc >> 1
            };
        }
    }
    !crc
}

/// `png` with an eXIf chunk holding `s`'s EXIF, right after the IHDR chunk.
fn png_with_exif(png: &[u8], s: Settings) -> Vec<u8> {
    let data = exif_bytes(s);
    let ihdr_end = 8 + 4 + 4 + 13 + 4;
    assert_eq!(&png[12..16], b"IHDR");
    let mut chunk = (data.len() as u32).to_be_bytes().to_vec();
    let mut typed = b"eXIf".to_vec();
    typed.extend(&data);
    chunk.extend(&typed);
    chunk.extend(crc32(&typed).to_be_bytes());
    let mut out = png[..ihdr_end].to_vec();
    out.extend(chunk);
    out.extend(&png[ihdr_end..]);
    out
}

/// The photo `png` as a JPEG with `s`'s EXIF in an APP1 segment right after SOI.
fn jpeg_with_exif(png: &Path, s: Settings) -> Vec<u8> {
    let img = image::open(png).unwrap().into_rgb8();
    let mut jpeg = Vec::new();
    img.write_to(&mut Cursor::new(&mut jpeg), image::ImageFormat::Jpeg)
        .unwrap();
    assert_eq!(&jpeg[..2], [0xff, 0xd8]);
    let mut payload = b"Exif\0\0".to_vec();
    payload.extend(exif_bytes(s));
    let mut out = vec![0xff, 0xd8, 0xff, 0xe1];
    out.extend(((payload.len() + 2) as u16).to_be_bytes());
    out.extend(payload);
    out.extend(&jpeg[2..]);
    out
}

/// The fit tests' scene and photo, and a folder for this test's files.
fn case(name: &str) -> (PathBuf, PathBuf, PathBuf) {
    let dir = common::temp_dir(name);
    let (scene, photo) = fit_case::good_case(&dir);
    (dir, scene, photo)
}

/// A quick fit: the paper's estimate with few samples.
fn fit_args(scene: &Path, photos: &[&Path], to: &[&str], exposure: &str) -> Vec<String> {
    let mut args = vec!["fit".to_owned(), arg(scene)];
    args.extend(photos.iter().map(|p| arg(p)));
    args.extend(to.iter().map(|s| s.to_string()));
    args.extend(
        [
            "--exposure",
            exposure,
            "--samples",
            SAMPLES_ARG,
            "--method",
            "paper",
        ]
        .map(String::from),
    );
    args
}

/// Asserts that `value` satisfies `schema/SCHEMA`.
fn assert_valid(value: &serde_json::Value, schema: &str) {
    let errors: Vec<String> = common::json::schema_validator(schema)
        .iter_errors(value)
        .map(|e| format!("{e} at {}", e.instance_path))
        .collect();
    assert!(errors.is_empty(), "{schema}: {errors:?}");
}

fn radiance(report: &serde_json::Value) -> [f64; 3] {
    let r = &report["lights"][0]["radiance"];
    [0, 1, 2].map(|k| r[k].as_f64().unwrap())
}

#[test]
fn each_photo_gets_the_exposure_of_its_exif() {
    let (dir, scene, photo) = case("exposure-exif-batch");
    let png = std::fs::read(&photo).unwrap();
    let a = dir.join("a.png");
    let b = dir.join("b.jpg");
    std::fs::write(&a, png_with_exif(&png, A)).unwrap();
    std::fs::write(&b, jpeg_with_exif(&photo, B)).unwrap();
    let out = dir.join("lit");
    let (code, stdout, stderr) = run(&fit_args(
        &scene,
        &[&a, &b],
        &["--out-dir", &arg(&out), "--json"],
        "auto",
    ));
    assert_eq!(code, 0, "{stderr}");
    let summary: serde_json::Value = serde_json::from_str(stdout.trim()).unwrap();
    assert_valid(&summary, "summary.schema.json");
    for (k, (name, settings, words)) in [
        ("a", A, "EXIF: 1/60 s, f/8, ISO 100"),
        ("b", B, "EXIF: 1/30 s, f/2.8, ISO 800"),
    ]
    .into_iter()
    .enumerate()
    {
        let report = read_json(&out.join(format!("{name}.report.json")));
        assert_valid(&report, "report.schema.json");
        let s = &report["settings"];
        let photo = &summary["photos"][k];
        assert_eq!(photo["exposure"], s["exposure"], "{summary}");
        assert_eq!(photo["exposure_source"], s["exposure_source"], "{summary}");
        let got = s["exposure"].as_f64().unwrap();
        let want = expected_exposure(settings);
        assert!(
            (got / want - 1.0).abs() < 1e-6,
            "{name}: exposure {got}, the equation gives {want}"
        );
        let source = s["exposure_source"].as_str().unwrap();
        assert!(source.starts_with(words), "{name}: {source}");
        assert!(
            stderr.contains(&format!("exposure {got}")) && stderr.contains(words),
            "the exposure is not printed: {stderr}"
        );
    }
    // The same photo with a given exposure: the radiance scales as 1 / exposure.
    let given = dir.join("given.report.json");
    let (code, _, stderr) = run(&fit_args(
        &scene,
        &[&photo],
        &[
            "-o",
            &arg(&dir.join("given.gltf")),
            "--report",
            &arg(&given),
        ],
        "0.1",
    ));
    assert_eq!(code, 0, "{stderr}");
    let given = read_json(&given);
    assert_eq!(given["settings"]["exposure_source"], "given");
    let auto = read_json(&out.join("a.report.json"));
    let (ra, rg) = (radiance(&auto), radiance(&given));
    let ratio = 0.1 / expected_exposure(A);
    for k in 0..3 {
        assert!(
            (ra[k] / rg[k] / ratio - 1.0).abs() < 1e-4,
            "radiance {ra:?} with the EXIF exposure, {rg:?} with 0.1: ratio not {ratio}"
        );
    }
}

#[test]
fn a_photo_without_the_exif_it_needs_is_refused_by_name() {
    let (dir, scene, photo) = case("exposure-exif-missing");
    let png = std::fs::read(&photo).unwrap();
    let no_iso = dir.join("no-iso.png");
    std::fs::write(&no_iso, png_with_exif(&png, Settings { iso: None, ..A })).unwrap();
    let no_time = dir.join("no-time.jpg");
    let settings = Settings { time: None, ..B };
    std::fs::write(&no_time, jpeg_with_exif(&photo, settings)).unwrap();
    let exr = dir.join("photo.exr");
    image::open(&photo)
        .unwrap()
        .into_rgb32f()
        .save(&exr)
        .unwrap();
    for (p, words) in [
        (&photo, "has no EXIF"),
        (&no_iso, "ISO speed"),
        (&no_time, "exposure time"),
        (&exr, "OpenEXR"),
    ] {
        let report = dir.join("report.json");
        let args = fit_args(
            &scene,
            &[p],
            &["-o", &arg(&dir.join("out.gltf")), "--report", &arg(&report)],
            "auto",
        );
        let (code, _, stderr) = run(&args);
        assert_eq!(code, 1, "{}: {stderr}", p.display());
        let name = p.file_name().unwrap().to_str().unwrap();
        assert!(
            stderr.contains(name) && stderr.contains(words) && stderr.contains("--exposure"),
            "{name}: {stderr}"
        );
        assert!(!dir.join("out.gltf").exists());
        // The refusal's report says why.
        let r = read_json(&report);
        assert!(r.to_string().contains(words), "{r}");
        // `segment` refuses it the same way.
        let (code, _, stderr) = run(&[
            "segment".into(),
            arg(&scene),
            arg(p),
            "--out-dir".into(),
            arg(&dir.join("streaks")),
            "--exposure".into(),
            "auto".into(),
        ]);
        assert_eq!(code, 1, "{stderr}");
        assert!(stderr.contains(name) && stderr.contains(words), "{stderr}");
    }
    // With its EXIF, `segment` reads and prints the exposure too.
    let good = dir.join("good.jpg");
    std::fs::write(&good, jpeg_with_exif(&photo, B)).unwrap();
    let (code, _, stderr) = run(&[
        "segment".into(),
        arg(&scene),
        arg(&good),
        "--out-dir".into(),
        arg(&dir.join("streaks")),
        "--exposure".into(),
        "auto".into(),
    ]);
    assert_eq!(code, 0, "{stderr}");
    let printed = format!("exposure {} (EXIF: 1/30 s", expected_exposure(B) as f32);
    assert!(stderr.contains(&printed), "{printed:?} not in {stderr}");
}
