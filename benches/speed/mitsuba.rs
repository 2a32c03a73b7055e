//! Mitsuba 3 for the speed bench: finding (or installing) a Python that runs its LLVM
//! variant, and timing its render of a scene in fresh processes (mitsuba_render.py).

use std::path::{Path, PathBuf};
use std::process::Command;

use crate::child::{run, Measured};

/// Mitsuba's render: the Table 1 photo's settings (64 spp), direct light off the water.
pub const SPP: u32 = 64;
/// Path depth: camera, water, light.
pub const DEPTH: u32 = 3;

/// A Python that runs Mitsuba's LLVM variant.
pub struct Mitsuba {
    pub python: PathBuf,
    pub libllvm: Option<PathBuf>,
    pub version: String,
}

/// The newest libLLVM of version 16 or later in the usual library folders.
fn find_libllvm() -> Option<PathBuf> {
    if let Some(p) = std::env::var_os("DRJIT_LIBLLVM_PATH") {
        return Some(PathBuf::from(p));
    }
    let mut best: Option<(u32, PathBuf)> = None;
    for dir in [
        "/usr/lib/x86_64-linux-gnu",
        "/usr/lib/aarch64-linux-gnu",
        "/usr/lib64",
        "/usr/lib",
        "/usr/local/lib",
    ] {
        let Ok(entries) = std::fs::read_dir(dir) else {
            continue;
        };
        for entry in entries.flatten() {
            let name = entry.file_name().to_string_lossy().into_owned();
            // libLLVM-19.so, libLLVM-19.so.1, libLLVM.so.19.1
            let Some(rest) = name.strip_prefix("libLLVM") else {
                continue;
            };
            let digits: String = rest
                .trim_start_matches(['-', '.'])
                .trim_start_matches("so.")
                .chars()
                .take_while(char::is_ascii_digit)
                .collect();
            let Ok(major) = digits.parse::<u32>() else {
                continue;
            };
            if major >= 16 && best.as_ref().is_none_or(|(m, _)| major > *m) {
                best = Some((major, entry.path()));
            }
        }
    }
    best.map(|(_, p)| p)
}

/// Mitsuba's version if `python` imports it and sets the LLVM variant, else why not.
fn probe(python: &Path, libllvm: Option<&Path>) -> Result<String, String> {
    let mut cmd = Command::new(python);
    cmd.args([
        "-c",
        "import numpy, mitsuba; mitsuba.set_variant('llvm_ad_rgb'); print(mitsuba.__version__)",
    ]);
    if let Some(l) = libllvm {
        cmd.env("DRJIT_LIBLLVM_PATH", l);
    }
    match cmd.output() {
        Ok(out) if out.status.success() => {
            Ok(String::from_utf8_lossy(&out.stdout).trim().to_owned())
        }
        Ok(out) => Err(format!(
            "{}: {}",
            python.display(),
            String::from_utf8_lossy(&out.stderr)
                .lines()
                .last()
                .unwrap_or("failed")
        )),
        Err(e) => Err(format!("{}: {e}", python.display())),
    }
}

/// Runs an install step, saying what it runs; why it failed if it did.
fn install_step(cmd: &mut Command) -> Result<(), String> {
    println!("mitsuba: running {cmd:?}");
    match cmd.output() {
        Ok(out) if out.status.success() => Ok(()),
        Ok(out) => Err(format!(
            "{cmd:?} failed: {}",
            String::from_utf8_lossy(&out.stderr)
                .lines()
                .last()
                .unwrap_or("")
        )),
        Err(e) => Err(format!("{cmd:?}: {e}")),
    }
}

/// Finds Mitsuba with its LLVM variant, installing it into `venv` if it is nowhere.
pub fn find_mitsuba(venv: &Path) -> Result<Mitsuba, String> {
    let venv_python = venv.join("bin/python");
    let mut candidates: Vec<PathBuf> = std::env::var_os("STREAKLIGHT_MITSUBA_PYTHON")
        .map(PathBuf::from)
        .into_iter()
        .collect();
    candidates.extend([venv_python.clone(), PathBuf::from("python3")]);
    let mut libllvm = find_libllvm();
    let mut why = Vec::new();
    for python in &candidates {
        match probe(python, libllvm.as_deref()) {
            Ok(version) => {
                return Ok(Mitsuba {
                    python: python.clone(),
                    libllvm,
                    version,
                })
            }
            Err(e) => why.push(e),
        }
    }
    if std::env::var_os("SPEED_BENCH_NO_INSTALL").is_some() {
        why.push("SPEED_BENCH_NO_INSTALL is set: not installing".into());
        return Err(why.join("; "));
    }
    if libllvm.is_none() {
        let root = unsafe { libc::geteuid() } == 0;
        let apt = |args: &[&str]| {
            let mut cmd = Command::new(if root { "apt-get" } else { "sudo" });
            if !root {
                cmd.args(["-n", "apt-get"]);
            }
            cmd.args(args).env("DEBIAN_FRONTEND", "noninteractive");
            cmd
        };
        let installed = install_step(&mut apt(&["update", "-qq"]))
            .and_then(|()| install_step(&mut apt(&["install", "-y", "-qq", "libllvm19"])));
        if let Err(e) = installed {
            why.push(e);
        }
        libllvm = find_libllvm();
        if libllvm.is_none() {
            why.push("no libLLVM 16 or newer (Mitsuba's LLVM variant needs one)".into());
            return Err(why.join("; "));
        }
    }
    let installed = if venv_python.exists() {
        Ok(())
    } else {
        install_step(Command::new("python3").arg("-m").arg("venv").arg(venv))
    }
    .and_then(|()| {
        install_step(Command::new(venv.join("bin/pip")).args(["install", "-q", "mitsuba", "numpy"]))
    });
    if let Err(e) = installed {
        why.push(e);
        return Err(why.join("; "));
    }
    probe(&venv_python, libllvm.as_deref())
        .map(|version| Mitsuba {
            python: venv_python,
            libllvm,
            version,
        })
        .map_err(|e| {
            why.push(e);
            why.join("; ")
        })
}

/// One Mitsuba run's seconds, as mitsuba_render.py prints them.
pub struct MitsubaRun {
    pub import: f64,
    pub read: f64,
    pub load: f64,
    pub render: f64,
    pub process: Measured,
    /// The shortest process wall time of the runs (the run kept is the one of the shortest
    /// [`Self::in_process`], which need not be it).
    pub best_wall: f64,
}

impl MitsubaRun {
    /// What a user waits for: the fresh process that imports Mitsuba, reads the scene, builds
    /// it and renders it, from spawn to exit (the fits are timed the same way). This is the
    /// anchor the targets are judged against.
    pub fn anchor(&self) -> f64 {
        self.best_wall
    }

    /// The stricter figure: reading the scene, building it and rendering it, timed inside
    /// the process (without the interpreter's start, the imports and the exit).
    pub fn in_process(&self) -> f64 {
        self.read + self.load + self.render
    }
}

/// Mitsuba's best of `runs` renders of `scene` at `width` x `height`, after a warm-up run
/// (which also fills Dr.Jit's kernel cache).
pub fn render(
    m: &Mitsuba,
    scene: &Path,
    (width, height): (u32, u32),
    runs: usize,
    dir: &Path,
) -> Result<MitsubaRun, String> {
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("benches/speed/mitsuba_render.py");
    let mut best: Option<MitsubaRun> = None;
    let mut best_wall = f64::INFINITY;
    for run_index in 0..=runs {
        let mut cmd = Command::new(&m.python);
        cmd.arg(&script)
            .arg(scene)
            .args([
                "--width",
                &width.to_string(),
                "--height",
                &height.to_string(),
            ])
            .args(["--spp", &SPP.to_string()])
            .args(["--max-depth", &DEPTH.to_string()]);
        if let Some(l) = &m.libllvm {
            cmd.env("DRJIT_LIBLLVM_PATH", l);
        }
        let process = run(&mut cmd, &dir.join("mitsuba.log"))?;
        let json: serde_json::Value = serde_json::from_str(process.stdout.trim())
            .map_err(|e| format!("mitsuba_render.py printed no JSON ({e})"))?;
        let seconds = |k: &str| json.get(k).and_then(|v| v.as_f64()).unwrap_or(f64::NAN);
        // The first run is the warm-up: it fills Dr.Jit's kernel cache.
        if run_index == 0 {
            continue;
        }
        best_wall = best_wall.min(process.wall);
        let this = MitsubaRun {
            import: seconds("import_s"),
            read: seconds("read_s"),
            load: seconds("load_s"),
            render: seconds("render_s"),
            process,
            best_wall: f64::NAN,
        };
        if best
            .as_ref()
            .is_none_or(|b| this.in_process() < b.in_process())
        {
            best = Some(this);
        }
    }
    best.map(|b| MitsubaRun { best_wall, ..b })
        .ok_or_else(|| "no run".into())
}
