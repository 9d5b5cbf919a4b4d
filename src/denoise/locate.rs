//! Where the Open Image Denoise library is looked for.
//!
//! An explicit setting wins, then the environment variable [`ENV_VAR`]; either is the only
//! place tried when given (a wrong setting is an error, not a reason to pick another copy).
//! Otherwise: beside the executable, `../lib` beside it (the add-on bundle's layout), the
//! `pyoidn` wheel in an active virtual environment, in a `.venv` of the executable's folder
//! or any ancestor (a checkout's `.venv` holds the executable's `target/` folder), in the
//! user's site-packages, and last the loader's own search path (`LD_LIBRARY_PATH`, ldconfig).

use std::path::{Path, PathBuf};

/// Environment variable naming the library file or the folder that holds it.
pub const ENV_VAR: &str = "TESELA_OIDN_LIB";

/// File names of the library in a folder, preferred first.
#[cfg(target_os = "macos")]
pub const FILE_NAMES: [&str; 2] = ["libOpenImageDenoise.2.dylib", "libOpenImageDenoise.dylib"];
#[cfg(windows)]
pub const FILE_NAMES: [&str; 1] = ["OpenImageDenoise.dll"];
#[cfg(not(any(target_os = "macos", windows)))]
pub const FILE_NAMES: [&str; 2] = ["libOpenImageDenoise.so.2", "libOpenImageDenoise.so"];

/// Where a candidate came from, for error messages.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Origin {
    Setting,
    Env,
    Search,
}

/// The places to try, in order. `explicit` and `env` are files or folders; a bare file name
/// (no folder) is passed to the loader as is, which searches its own path.
pub fn candidates(
    explicit: Option<&Path>,
    env: Option<&Path>,
    exe: Option<&Path>,
    home: Option<&Path>,
    venv: Option<&Path>,
) -> (Origin, Vec<PathBuf>) {
    if let Some(p) = explicit {
        return (Origin::Setting, expand(p));
    }
    if let Some(p) = env.filter(|p| !p.as_os_str().is_empty()) {
        return (Origin::Env, expand(p));
    }
    let mut dirs = Vec::new();
    if let Some(exe_dir) = exe.and_then(Path::parent) {
        dirs.push(exe_dir.to_path_buf());
        dirs.push(exe_dir.join("../lib"));
    }
    if let Some(v) = venv {
        dirs.extend(wheel_dirs(v));
    }
    for dir in exe
        .and_then(Path::parent)
        .into_iter()
        .flat_map(Path::ancestors)
    {
        dirs.extend(wheel_dirs(&dir.join(".venv")));
    }
    if let Some(h) = home {
        dirs.extend(wheel_dirs(&h.join(".local")));
    }
    let mut out: Vec<PathBuf> = dirs
        .iter()
        .flat_map(|d| FILE_NAMES.iter().map(move |n| d.join(n)))
        .collect();
    out.extend(FILE_NAMES.iter().map(PathBuf::from));
    (Origin::Search, out)
}

/// A folder expands to the library's file names in it; anything else is taken as the file.
fn expand(p: &Path) -> Vec<PathBuf> {
    if p.is_dir() {
        FILE_NAMES.iter().map(|n| p.join(n)).collect()
    } else {
        vec![p.to_path_buf()]
    }
}

/// `pyoidn`'s library folders in the Python prefix `prefix` (a venv or `~/.local`), one per
/// `lib/python3.*` present.
fn wheel_dirs(prefix: &Path) -> Vec<PathBuf> {
    let Ok(entries) = std::fs::read_dir(prefix.join("lib")) else {
        return Vec::new();
    };
    let mut dirs: Vec<PathBuf> = entries
        .flatten()
        .filter(|e| e.file_name().to_string_lossy().starts_with("python3"))
        .map(|e| e.path().join("site-packages/pyoidn/oidn/lib"))
        .filter(|d| d.is_dir())
        .collect();
    dirs.sort();
    dirs
}

/// Whether the loader should be asked for `p` (it exists, or it is a bare name that the
/// loader resolves through its search path).
pub fn worth_trying(p: &Path) -> bool {
    p.components().count() == 1 || p.exists()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scratch(name: &str) -> PathBuf {
        let d = std::env::temp_dir().join(format!("tesela-locate-{}-{name}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        std::fs::create_dir_all(&d).unwrap();
        d
    }

    #[test]
    fn explicit_setting_and_env_var_are_the_only_candidates() {
        let dir = scratch("explicit");
        let (o, c) = candidates(Some(&dir), Some(Path::new("/env")), None, None, None);
        assert_eq!(o, Origin::Setting);
        assert_eq!(c, FILE_NAMES.map(|n| dir.join(n)).to_vec());
        let file = dir.join("custom.so");
        let (o, c) = candidates(None, Some(&file), None, None, None);
        assert_eq!((o, c), (Origin::Env, vec![file]));
        // An empty variable counts as unset.
        let (o, _) = candidates(None, Some(Path::new("")), None, None, None);
        assert_eq!(o, Origin::Search);
    }

    #[test]
    fn search_order_is_exe_dir_bundle_lib_then_wheels_then_loader_path() {
        let root = scratch("search");
        let exe = root.join("target/release/tesela");
        let wheel = root.join(".venv/lib/python3.11/site-packages/pyoidn/oidn/lib");
        std::fs::create_dir_all(&wheel).unwrap();
        let (o, c) = candidates(None, None, Some(&exe), None, None);
        assert_eq!(o, Origin::Search);
        let n = FILE_NAMES.len();
        let release = root.join("target/release");
        assert_eq!(c[0], release.join(FILE_NAMES[0]));
        assert_eq!(c[n], release.join("../lib").join(FILE_NAMES[0]));
        assert_eq!(c[2 * n], wheel.join(FILE_NAMES[0]));
        assert_eq!(c[c.len() - n], PathBuf::from(FILE_NAMES[0]));
        assert!(worth_trying(&c[c.len() - 1]));
        assert!(!worth_trying(&c[0]));
    }
}
