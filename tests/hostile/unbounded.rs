//! Class 4: nothing hangs and nothing is unbounded: a FIFO, a device or a folder as the scene,
//! the photo or a buffer is refused within a second; the bytes read and the memory a photo
//! needs are bounded by limits a user can raise; options that set the work are capped before
//! any work.

use std::path::Path;

use crate::common::cli::arg;
use crate::support::{case, fit, refused};

#[cfg(unix)]
fn fifo(path: &Path) {
    let c = std::ffi::CString::new(path.to_str().unwrap()).unwrap();
    // SAFETY: mkfifo(3) on a NUL-terminated path.
    assert_eq!(unsafe { libc::mkfifo(c.as_ptr(), 0o644) }, 0);
}

/// `args` with `--exposure auto` in place of the exposure they give.
#[cfg(unix)]
fn exposure_auto(mut args: Vec<String>) -> Vec<String> {
    let at = args.iter().position(|a| a == "--exposure").unwrap();
    args[at + 1] = "auto".into();
    args
}

#[cfg(unix)]
#[test]
fn fifos_and_devices_are_refused_within_a_second() {
    let c = case("hostile-fifo");
    let pipe = c.dir.join("pipe.gltf");
    fifo(&pipe);
    let out = c.dir.join("out.gltf");
    let zero = Path::new("/dev/zero");
    let cases: Vec<(Vec<String>, &str)> = vec![
        (fit(&pipe, &c.photo, &["-o", &arg(&out)]), "FIFO"),
        (fit(&c.scene, &pipe, &["-o", &arg(&out)]), "FIFO"),
        (fit(zero, &c.photo, &["-o", &arg(&out)]), "device"),
        (fit(&c.scene, zero, &["-o", &arg(&out)]), "device"),
        (fit(&c.scene, &c.dir, &["-o", &arg(&out)]), "folder"),
        // `--exposure auto` reads the photo's EXIF before the photo itself.
        (
            exposure_auto(fit(&c.scene, &pipe, &["-o", &arg(&out)])),
            "FIFO",
        ),
        (
            exposure_auto(fit(&c.scene, zero, &["-o", &arg(&out)])),
            "device",
        ),
    ];
    for (args, word) in cases {
        let ran = refused(&args, &[], &[&c.dir], &[word, "regular files"]);
        assert!(ran.seconds < 1.0, "{args:?}: {} s", ran.seconds);
    }
    // A buffer naming /dev/zero.
    let mut doc: serde_json::Value =
        serde_json::from_slice(&std::fs::read(&c.scene).unwrap()).unwrap();
    doc["buffers"][0]["uri"] = "/dev/zero".into();
    std::fs::write(&c.scene, serde_json::to_vec(&doc).unwrap()).unwrap();
    let ran = refused(
        &fit(&c.scene, &c.photo, &["-o", &arg(&out)]),
        &[],
        &[&c.dir],
        &["device"],
    );
    assert!(ran.seconds < 1.0, "{} s", ran.seconds);
}

#[test]
fn the_input_and_memory_limits_refuse_and_say_how_to_raise_them() {
    let c = case("hostile-limits");
    let out = c.dir.join("out.gltf");
    let args = fit(&c.scene, &c.photo, &["-o", &arg(&out)]);
    // The scene's buffer is some 100 KB: a limit of 0 is refused as a value, 1 MiB passes it.
    refused(
        &args,
        &[("STREAKLIGHT_MAX_INPUT_MB", "0")],
        &[&c.dir],
        &["STREAKLIGHT_MAX_INPUT_MB"],
    );
    let big = c.dir.join("big.png");
    let noise: Vec<u8> = (0..900 * 900 * 3u32)
        .map(|i| (i.wrapping_mul(2_654_435_761) >> 13) as u8)
        .collect();
    image::RgbImage::from_raw(900, 900, noise)
        .unwrap()
        .save(&big)
        .unwrap();
    let args = fit(&c.scene, &big, &["-o", &arg(&out)]);
    refused(
        &args,
        &[("STREAKLIGHT_MAX_INPUT_MB", "1")],
        &[&c.dir],
        &[
            "big.png",
            "larger than the input limit of 1 MiB",
            "STREAKLIGHT_MAX_INPUT_MB",
        ],
    );
    // The 160 x 160 photo needs about 1.2 MiB by the estimate.
    let args = fit(&c.scene, &c.photo, &["-o", &arg(&out)]);
    refused(
        &args,
        &[("STREAKLIGHT_MAX_MEMORY_MB", "1")],
        &[&c.dir],
        &["photo.png", "160 x 160", "STREAKLIGHT_MAX_MEMORY_MB"],
    );
}

#[test]
fn options_above_their_caps_are_refused_before_any_work() {
    let c = case("hostile-caps");
    let out = arg(&c.dir.join("out.gltf"));
    let scene = arg(&c.scene);
    let image = arg(&c.dir.join("r.png"));
    let cases: Vec<(Vec<String>, &str)> = vec![
        (
            fit(
                &c.scene,
                &c.photo,
                &["-o", &out, "--joint-samples", "4294967295"],
            ),
            "--joint-samples 4294967295",
        ),
        (
            fit(&c.scene, &c.photo, &["-o", &out])
                .into_iter()
                .map(|a| if a == "64" { "4000000000".into() } else { a })
                .collect(),
            "--samples 4000000000",
        ),
        (
            fit(&c.scene, &c.photo, &["-o", &out, "--repeats", "100000"]),
            "--repeats 100000",
        ),
        (
            [
                "render", &scene, "-o", &image, "--width", "32768", "--height", "32768",
            ]
            .map(String::from)
            .to_vec(),
            "--width 32768",
        ),
        (
            ["render", &scene, "-o", &image, "--spp", "100000000"]
                .map(String::from)
                .to_vec(),
            "--spp 100000000",
        ),
        (
            [
                "render", &scene, "-o", &image, "--width", "8000", "--height", "8000", "--spp",
                "60000",
            ]
            .map(String::from)
            .to_vec(),
            "camera rays",
        ),
        (
            ["samples", &arg(&c.dir.join("s")), "--spp", "4000000000"]
                .map(String::from)
                .to_vec(),
            "--spp 4000000000",
        ),
    ];
    for (args, word) in cases {
        let ran = refused(&args, &[], &[&c.dir], &[word, "cap"]);
        assert_eq!(ran.code, Some(2), "{args:?}");
        assert!(ran.seconds < 1.0, "{args:?}: {} s", ran.seconds);
    }
}
