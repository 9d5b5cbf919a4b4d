//! The few functions of Open Image Denoise's 2.x C API that Tesela calls, resolved at run time
//! from a library opened with `dlopen`, so that Tesela builds and runs without it.
//!
//! Signatures follow `OpenImageDenoise/oidn.h` of OIDN 2.x (the version PyPI's `pyoidn` ships);
//! C enums are passed as `c_int`.

use std::ffi::{CStr, CString, c_char, c_int, c_void};
use std::path::Path;

pub type Device = *mut c_void;
pub type Buffer = *mut c_void;
pub type Filter = *mut c_void;

pub const DEVICE_TYPE_DEFAULT: c_int = 0;
pub const FORMAT_FLOAT3: c_int = 3;

/// Declares [`Api`] (one function pointer per entry) and `Api::resolve`, which looks each
/// entry's symbol up and casts it to the entry's signature.
macro_rules! api {
    ($($field:ident = $symbol:literal: ($($arg:ty),*) $(-> $ret:ty)?;)*) => {
        /// Function pointers into one opened OIDN library.
        pub struct Api {
            $(pub $field: unsafe extern "C" fn($($arg),*) $(-> $ret)?,)*
        }

        impl Api {
            #[cfg(unix)]
            fn resolve(
                sym: impl Fn(&'static CStr) -> Result<*mut c_void, OpenError>,
            ) -> Result<Api, OpenError> {
                Ok(Api {
                    $($field: {
                        let p = sym($symbol)?;
                        // SAFETY: `p` is the non-null address of this function in a library
                        // exporting the OIDN 2.x C API, whose header declares it with exactly
                        // this signature.
                        unsafe {
                            std::mem::transmute::<*mut c_void, unsafe extern "C" fn($($arg),*) $(-> $ret)?>(p)
                        }
                    },)*
                })
            }
        }
    };
}

api! {
    new_device = c"oidnNewDevice": (c_int) -> Device;
    set_device_int = c"oidnSetDeviceInt": (Device, *const c_char, c_int);
    get_device_int = c"oidnGetDeviceInt": (Device, *const c_char) -> c_int;
    commit_device = c"oidnCommitDevice": (Device);
    release_device = c"oidnReleaseDevice": (Device);
    get_device_error = c"oidnGetDeviceError": (Device, *mut *const c_char) -> c_int;
    new_buffer = c"oidnNewBuffer": (Device, usize) -> Buffer;
    write_buffer = c"oidnWriteBuffer": (Buffer, usize, usize, *const c_void);
    read_buffer = c"oidnReadBuffer": (Buffer, usize, usize, *mut c_void);
    release_buffer = c"oidnReleaseBuffer": (Buffer);
    new_filter = c"oidnNewFilter": (Device, *const c_char) -> Filter;
    // (filter, name, buffer, format, width, height, byteOffset, pixelByteStride, rowByteStride)
    set_filter_image = c"oidnSetFilterImage":
        (Filter, *const c_char, Buffer, c_int, usize, usize, usize, usize, usize);
    set_filter_bool = c"oidnSetFilterBool": (Filter, *const c_char, bool);
    commit_filter = c"oidnCommitFilter": (Filter);
    execute_filter = c"oidnExecuteFilter": (Filter);
    release_filter = c"oidnReleaseFilter": (Filter);
}

/// Why a file could not serve as the OIDN library.
pub enum OpenError {
    /// `dlopen` refused it (missing, not a shared library, wrong architecture, missing
    /// dependencies): the loader's message.
    Load(String),
    /// It loaded but lacks this symbol (not OIDN, or a version without the 2.x API).
    Symbol(&'static str),
}

/// Opens `path` (a file, or a bare name for the loader's search path) and resolves [`Api`].
///
/// A library that resolves is never closed: OIDN starts worker threads (TBB) that must not
/// outlive its code, and the loader shares one copy per process anyway.
#[cfg(unix)]
pub fn open(path: &Path) -> Result<Api, OpenError> {
    use std::os::unix::ffi::OsStrExt;
    if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
        super::elf::check_length(path).map_err(OpenError::Load)?;
        preload_dependencies(dir)?;
    }
    let handle = dlopen(path.as_os_str().as_bytes())?;
    let sym = |name: &'static CStr| -> Result<*mut c_void, OpenError> {
        // SAFETY: `handle` is a live handle from dlopen and `name` a C string.
        let p = unsafe { libc::dlsym(handle, name.as_ptr()) };
        if p.is_null() {
            Err(OpenError::Symbol(name.to_str().unwrap_or("?")))
        } else {
            Ok(p)
        }
    };
    let api = Api::resolve(sym);
    if api.is_err() {
        // SAFETY: nothing of this library is in use (it is not OIDN and no symbol was kept).
        unsafe { libc::dlclose(handle) };
    }
    api
}

/// Opens a shared library, which runs its initialisers.
#[cfg(unix)]
fn dlopen(path: &[u8]) -> Result<*mut c_void, OpenError> {
    let c_path =
        CString::new(path).map_err(|_| OpenError::Load("the path contains a NUL byte".into()))?;
    // SAFETY: `c_path` is a valid C string; dlopen runs the library's initialisers, which is
    // what loading a denoiser means (a file that is not a shared library is refused by it).
    let handle = unsafe { libc::dlopen(c_path.as_ptr(), libc::RTLD_NOW | libc::RTLD_LOCAL) };
    if handle.is_null() {
        Err(OpenError::Load(last_dl_error()))
    } else {
        Ok(handle)
    }
}

/// Loads OIDN's own dependencies found in `dir` (TBB, then the core library), so that the
/// main library's references to them resolve to these files by their names wherever `dir`
/// is: its run path is `$ORIGIN/../lib`, which only finds them in a folder named `lib`.
/// Load failures are left for the main library's load to report; a truncated file is refused.
#[cfg(unix)]
fn preload_dependencies(dir: &Path) -> Result<(), OpenError> {
    use std::os::unix::ffi::OsStrExt;
    let Ok(entries) = std::fs::read_dir(dir) else {
        return Ok(());
    };
    let mut names: Vec<_> = entries.flatten().map(|e| e.file_name()).collect();
    names.sort();
    // (Exact TBB name: the wheel also holds a copy as libtbb.so.12.19, which must not load twice.)
    let wanted = [
        |n: &[u8]| n == b"libtbb.so.12",
        |n: &[u8]| n.starts_with(b"libOpenImageDenoise_core.so."),
    ];
    for wanted in wanted {
        for name in names.iter().filter(|n| wanted(n.as_bytes())) {
            let path = dir.join(name);
            super::elf::check_length(&path)
                .map_err(|e| OpenError::Load(format!("{}: {e}", path.display())))?;
            // Kept open for the process's lifetime, like the library itself.
            let _ = dlopen(path.as_os_str().as_bytes());
        }
    }
    Ok(())
}

#[cfg(not(unix))]
pub fn open(_path: &Path) -> Result<Api, OpenError> {
    Err(OpenError::Load(
        "loading Open Image Denoise at run time is implemented for Unix systems only".into(),
    ))
}

#[cfg(unix)]
fn last_dl_error() -> String {
    // SAFETY: dlerror returns null or a C string valid until the next dl* call on this thread.
    let msg = unsafe { libc::dlerror() };
    if msg.is_null() {
        "unknown dlopen error".into()
    } else {
        // SAFETY: non-null, NUL-terminated (see above); copied out at once.
        unsafe { CStr::from_ptr(msg) }
            .to_string_lossy()
            .into_owned()
    }
}

/// Turns a C message pointer from OIDN into a `String`.
///
/// # Safety
/// `msg` is null or a NUL-terminated string that stays valid during the call.
pub unsafe fn message(msg: *const c_char) -> String {
    if msg.is_null() {
        String::new()
    } else {
        // SAFETY: by the caller's contract.
        unsafe { CStr::from_ptr(msg) }
            .to_string_lossy()
            .into_owned()
    }
}
