//! What the hostile tests share: a small fit case with an external buffer, snapshots of
//! folders, and runs of the binary with a deadline.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use crate::common::cli::{arg, EXPOSURE_ARG};
use crate::common::fit_case;

/// A case: `scene.gltf` whose buffer is the file `water.bin` beside it, and `photo.png`.
pub struct Case {
    pub dir: PathBuf,
    pub scene: PathBuf,
    pub bin: PathBuf,
    pub photo: PathBuf,
}

/// The photo and the scene are made once per test binary and copied into each case's folder.
pub fn case(name: &str) -> Case {
    static MADE: std::sync::OnceLock<(PathBuf, PathBuf)> = std::sync::OnceLock::new();
    let (scene_json, photo) = MADE.get_or_init(|| {
        let dir = crate::common::temp_dir("hostile-source");
        let (_, photo) = fit_case::good_case(&dir);
        let scene = dir.join("external.gltf");
        crate::common::paper_setup(Some(fit_case::water_material()))
            .write_gltf_external(&scene, "water.bin");
        (scene, photo)
    });
    let source = scene_json.parent().unwrap();
    let dir = crate::common::temp_dir(name);
    std::fs::copy(scene_json, dir.join("scene.gltf")).unwrap();
    std::fs::copy(source.join("water.bin"), dir.join("water.bin")).unwrap();
    std::fs::copy(photo, dir.join("photo.png")).unwrap();
    Case {
        scene: dir.join("scene.gltf"),
        bin: dir.join("water.bin"),
        photo: dir.join("photo.png"),
        dir,
    }
}

/// `fit SCENE PHOTO` with the test exposure and few samples, then `extra`.
pub fn fit(scene: &Path, photo: &Path, extra: &[&str]) -> Vec<String> {
    let mut args = vec![
        "fit".to_string(),
        arg(scene),
        arg(photo),
        "--exposure".into(),
        EXPOSURE_ARG.into(),
        "--samples".into(),
        "64".into(),
    ];
    args.extend(extra.iter().map(|s| s.to_string()));
    args
}

/// Every file under `dir` (recursively; symlinks as their targets' paths) with its bytes. A
/// file that vanishes while it is read (a running fit renaming or removing its temporaries,
/// as the interrupt tests watch it do) is left out.
pub fn snapshot(dir: &Path) -> BTreeMap<PathBuf, Vec<u8>> {
    let mut out = BTreeMap::new();
    let Ok(entries) = std::fs::read_dir(dir) else {
        return out;
    };
    // The value, or `None` for a file gone since it was listed; any other error fails.
    fn present<T>(r: std::io::Result<T>) -> Option<T> {
        match r {
            Ok(v) => Some(v),
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => None,
            Err(e) => panic!("{e}"),
        }
    }
    for e in entries {
        let Some(e) = present(e) else { continue };
        let path = e.path();
        let Some(meta) = present(std::fs::symlink_metadata(&path)) else {
            continue;
        };
        if meta.file_type().is_symlink() {
            let Some(target) = present(std::fs::read_link(&path)) else {
                continue;
            };
            out.insert(path, target.to_string_lossy().as_bytes().to_vec());
        } else if meta.is_dir() {
            out.insert(path.clone(), b"<folder>".to_vec());
            out.extend(snapshot(&path));
        } else if meta.is_file() {
            let Some(bytes) = present(std::fs::read(&path)) else {
                continue;
            };
            out.insert(path.clone(), bytes);
        } else {
            out.insert(path, b"<special>".to_vec());
        }
    }
    out
}

/// Asserts two snapshots equal, naming the files that differ.
pub fn assert_same(before: &BTreeMap<PathBuf, Vec<u8>>, after: &BTreeMap<PathBuf, Vec<u8>>) {
    let changed: Vec<_> = before
        .keys()
        .chain(after.keys())
        .filter(|k| before.get(*k) != after.get(*k))
        .collect();
    assert!(changed.is_empty(), "changed: {changed:?}");
}

/// The outcome of a run.
pub struct Ran {
    pub code: Option<i32>,
    pub stderr: String,
    pub seconds: f64,
}

/// Runs the binary with `args` (and `env`), killing it after `deadline` seconds.
pub fn run_with(args: &[String], env: &[(&str, &str)], deadline: f64) -> Ran {
    let start = Instant::now();
    let mut child = Command::new(env!("CARGO_BIN_EXE_streaklight"))
        .args(args)
        .envs(env.iter().copied())
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    loop {
        if child.try_wait().unwrap().is_some() {
            break;
        }
        if start.elapsed().as_secs_f64() > deadline {
            child.kill().unwrap();
            break;
        }
        std::thread::sleep(Duration::from_millis(5));
    }
    let out = child.wait_with_output().unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr).into_owned();
    assert!(!stderr.contains("panicked"), "panic on {args:?}: {stderr}");
    Ran {
        code: out.status.code(),
        stderr,
        seconds: start.elapsed().as_secs_f64(),
    }
}

/// Runs `args`; asserts a refusal (exit 1, 2 or 3) whose message holds every one of `words`, and
/// that the snapshot of every folder in `watch` is unchanged.
pub fn refused(args: &[String], env: &[(&str, &str)], watch: &[&Path], words: &[&str]) -> Ran {
    let before: Vec<_> = watch.iter().map(|d| snapshot(d)).collect();
    let ran = run_with(args, env, 60.0);
    assert!(
        matches!(ran.code, Some(1..=3)),
        "{args:?} exited {:?}: {}",
        ran.code,
        ran.stderr
    );
    for w in words {
        assert!(ran.stderr.contains(w), "no \"{w}\" in: {}", ran.stderr);
    }
    for (d, b) in watch.iter().zip(&before) {
        assert_same(b, &snapshot(d));
    }
    ran
}

/// The temporary files of streaklight in `dir` (recursively).
pub fn temporaries(dir: &Path) -> Vec<PathBuf> {
    snapshot(dir)
        .into_keys()
        .filter(|p| {
            p.file_name()
                .is_some_and(|n| n.to_string_lossy().contains("tmp-streaklight"))
        })
        .collect()
}
