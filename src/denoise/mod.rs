//! Denoising with Intel Open Image Denoise (OIDN), the denoiser of Cycles and Blender's
//! compositor: its "RT" filter on the linear HDR beauty, guided by albedo and normal images.
//!
//! The library is opened at run time (see [`locate`] for where it is looked for), so Tesela
//! builds and renders without it; [`Denoiser::load`] then says why denoising is unavailable.
//! PyPI's `pyoidn` wheel ships it (`pip install pyoidn`, folder `pyoidn/oidn/lib`).
//!
//! With `prefilter`, as Cycles' "Accurate" prefilter does, the albedo and normal images are
//! first denoised on their own (an RT filter with only that image as input), and the beauty
//! filter is told they are clean (`cleanAux`), which keeps their noise out of the result.

#[cfg(unix)]
mod elf;
pub mod locate;
mod oidn;

pub use locate::ENV_VAR;

use std::ffi::{CStr, c_char, c_void};
use std::fmt;
use std::path::{Path, PathBuf};
use std::sync::Mutex;

/// Why denoising could not be done.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum DenoiseError {
    /// No usable library: not found, not loadable, not OIDN 2.x, or no device could be made.
    Unavailable(String),
    /// The images handed to [`Denoiser::denoise`] do not fit together.
    Input(String),
    /// OIDN reported an error while filtering.
    Device(String),
}

impl fmt::Display for DenoiseError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            DenoiseError::Unavailable(m) => write!(f, "denoising unavailable: {m}"),
            DenoiseError::Input(m) => write!(f, "denoiser input: {m}"),
            DenoiseError::Device(m) => write!(f, "Open Image Denoise: {m}"),
        }
    }
}

impl std::error::Error for DenoiseError {}

/// Images to denoise: `width × height` pixels, rows top to bottom, 3 interleaved `f32`
/// channels each.
#[derive(Clone, Copy, Debug)]
pub struct Input<'a> {
    pub width: usize,
    pub height: usize,
    /// Linear HDR radiance (the beauty), values ≥ 0.
    pub color: &'a [f32],
    /// Albedo at the first visible surface, in [0, 1].
    pub albedo: Option<&'a [f32]>,
    /// Shading normal at the first visible surface, components in [-1, 1] (any space, any
    /// length; 0 where nothing was hit). OIDN accepts it only together with `albedo`.
    pub normal: Option<&'a [f32]>,
}

impl Input<'_> {
    /// Checks sizes and combinations before anything is allocated.
    pub fn check(&self) -> Result<(), DenoiseError> {
        let bad = |m: String| Err(DenoiseError::Input(m));
        if self.width == 0 || self.height == 0 {
            return bad(format!(
                "image size {}x{} is empty",
                self.width, self.height
            ));
        }
        let pixels = self.width.checked_mul(self.height);
        let Some(pixels) = pixels.filter(|&p| p as u64 <= crate::render::MAX_PIXELS) else {
            return bad(format!(
                "image size {}x{} is too large (at most {} pixels)",
                self.width,
                self.height,
                crate::render::MAX_PIXELS
            ));
        };
        let images = [
            ("color", Some(self.color)),
            ("albedo", self.albedo),
            ("normal", self.normal),
        ];
        for (name, image) in images {
            if let Some(image) = image
                && image.len() != 3 * pixels
            {
                return bad(format!(
                    "the {name} image has {} values, {}x{} RGB needs {}",
                    image.len(),
                    self.width,
                    self.height,
                    3 * pixels
                ));
            }
        }
        if self.normal.is_some() && self.albedo.is_none() {
            return bad("a normal image needs an albedo image too".into());
        }
        Ok(())
    }
}

/// What each input image may hold; anything else is replaced before OIDN sees it, so that a
/// NaN or infinity in a buffer cannot spread over its neighbours through the network.
#[derive(Clone, Copy)]
enum Kind {
    /// Finite and ≥ 0; anything else becomes 0.
    Color,
    /// Clamped to [0, 1]; non-finite becomes 0.
    Albedo,
    /// Clamped to [-1, 1]; non-finite becomes 0 ("no surface").
    Normal,
}

/// A copy of `values` with out-of-range values replaced as [`Kind`] says.
fn sanitized(values: &[f32], kind: Kind) -> Vec<f32> {
    let (lo, hi) = match kind {
        Kind::Color => (0.0, f32::MAX),
        Kind::Albedo => (0.0, 1.0),
        Kind::Normal => (-1.0, 1.0),
    };
    values
        .iter()
        .map(|&v| if v.is_finite() { v.clamp(lo, hi) } else { 0.0 })
        .collect()
}

/// An opened OIDN library with a committed device.
pub struct Denoiser {
    api: oidn::Api,
    device: oidn::Device,
    path: PathBuf,
    version: i32,
    device_type: i32,
    threads: usize,
    /// Serializes filtering so that the device's error slot belongs to one call at a time.
    lock: Mutex<()>,
}

// SAFETY: OIDN's API is thread-safe ("all API calls are thread-safe, but operations that use
// the same device will be serialized"); the device pointer is only used through it, and
// `denoise` takes `lock` besides.
unsafe impl Send for Denoiser {}
// SAFETY: as above.
unsafe impl Sync for Denoiser {}

impl Drop for Denoiser {
    fn drop(&mut self) {
        // SAFETY: `device` is a device of this library, released exactly once here; filters and
        // buffers never outlive a `denoise` call.
        unsafe { (self.api.release_device)(self.device) };
    }
}

/// A buffer or filter handle, released when dropped (also on early returns).
struct Handle {
    ptr: *mut c_void,
    release: unsafe extern "C" fn(*mut c_void),
}

impl Drop for Handle {
    fn drop(&mut self) {
        // SAFETY: `ptr` is a live handle created by the library that `release` belongs to,
        // released exactly once.
        unsafe { (self.release)(self.ptr) };
    }
}

impl Denoiser {
    /// Opens the library and creates its default device (a GPU when OIDN finds a supported one,
    /// else the CPU) with `threads` worker threads (0 = all cores; CPU device only).
    ///
    /// `library` is a file or a folder; without it [`ENV_VAR`] is used, and without that the
    /// search of [`locate`]. Errors name the paths tried, a missing symbol, an unsupported
    /// version or the device's message.
    pub fn load(library: Option<&Path>, threads: usize) -> Result<Denoiser, DenoiseError> {
        let env = std::env::var_os(ENV_VAR).map(PathBuf::from);
        let exe = std::env::current_exe().ok();
        let home = std::env::var_os("HOME").map(PathBuf::from);
        let venv = std::env::var_os("VIRTUAL_ENV").map(PathBuf::from);
        let (origin, candidates) = locate::candidates(
            library,
            env.as_deref(),
            exe.as_deref(),
            home.as_deref(),
            venv.as_deref(),
        );
        let source = match origin {
            locate::Origin::Setting => "the denoiser library setting",
            locate::Origin::Env => ENV_VAR,
            locate::Origin::Search => "the search",
        };
        let unavailable = |m: String| Err(DenoiseError::Unavailable(m));
        let mut tried = Vec::new();
        for path in &candidates {
            if !locate::worth_trying(path) {
                tried.push(format!("{} (absent)", path.display()));
                continue;
            }
            match oidn::open(path) {
                Ok(api) => return Denoiser::with_device(api, path, threads),
                // A bare name is the loader's search, which may simply not have it.
                Err(oidn::OpenError::Load(m)) if path.components().count() == 1 => {
                    tried.push(format!("{} ({m})", path.display()));
                }
                Err(oidn::OpenError::Load(m)) => {
                    return unavailable(format!(
                        "{} (from {source}) is not a loadable library: {m}",
                        path.display()
                    ));
                }
                Err(oidn::OpenError::Symbol(s)) => {
                    return unavailable(format!(
                        "{} (from {source}) is not Open Image Denoise 2.x: it has no symbol {s}",
                        path.display()
                    ));
                }
            }
        }
        unavailable(format!(
            "Open Image Denoise not found (from {source}; tried {}); install PyPI's pyoidn \
             (pip install pyoidn) or set {ENV_VAR} to the library or its folder",
            tried.join(", ")
        ))
    }

    fn with_device(api: oidn::Api, path: &Path, threads: usize) -> Result<Denoiser, DenoiseError> {
        let fail = |m: String| DenoiseError::Unavailable(format!("{}: {m}", path.display()));
        // SAFETY: the functions come from a library exporting the OIDN 2.x API; a null device
        // is only passed to oidnGetDeviceError, which documents null as "this thread's error".
        let device = unsafe { (api.new_device)(oidn::DEVICE_TYPE_DEFAULT) };
        if device.is_null() {
            let mut msg: *const c_char = std::ptr::null();
            // SAFETY: as above; the message is copied before any other call.
            let code = unsafe { (api.get_device_error)(device, &mut msg) };
            // SAFETY: OIDN returns null or a C string valid until its next call.
            let msg = unsafe { oidn::message(msg) };
            return Err(fail(format!(
                "no device could be created: {msg} (error {code})"
            )));
        }
        let mut d = Denoiser {
            api,
            device,
            path: path.to_path_buf(),
            version: 0,
            device_type: 0,
            threads,
            lock: Mutex::new(()),
        };
        let threads =
            i32::try_from(threads).map_err(|_| fail(format!("{threads} threads is too many")))?;
        // SAFETY: `device` is a live device; the names are C strings.
        unsafe {
            if threads > 0 {
                (d.api.set_device_int)(device, c"numThreads".as_ptr(), threads);
            }
            (d.api.commit_device)(device);
        }
        d.check("device setup").map_err(|e| fail(e.to_string()))?;
        // SAFETY: as above.
        unsafe {
            d.version = (d.api.get_device_int)(device, c"version".as_ptr());
            d.device_type = (d.api.get_device_int)(device, c"type".as_ptr());
        }
        if d.version / 10000 != 2 {
            return Err(fail(format!(
                "version {} is not supported (Tesela uses the 2.x API)",
                d.version_string()
            )));
        }
        Ok(d)
    }

    /// The library file in use.
    pub fn library_path(&self) -> &Path {
        &self.path
    }

    /// OIDN's version as (major, minor, patch).
    pub fn version(&self) -> (i32, i32, i32) {
        (
            self.version / 10000,
            self.version / 100 % 100,
            self.version % 100,
        )
    }

    fn version_string(&self) -> String {
        let (a, b, c) = self.version();
        format!("{a}.{b}.{c}")
    }

    /// One line for logs: version, device, threads and library file.
    pub fn describe(&self) -> String {
        let device = match self.device_type {
            1 => "CPU",
            2 => "SYCL",
            3 => "CUDA",
            4 => "HIP",
            5 => "Metal",
            _ => "unknown",
        };
        let threads = match self.threads {
            0 => "all threads".to_string(),
            1 => "1 thread".to_string(),
            n => format!("{n} threads"),
        };
        format!(
            "Open Image Denoise {} ({device} device, {threads}) from {}",
            self.version_string(),
            self.path.display()
        )
    }

    /// The first error the device recorded since the last check, if any.
    fn check(&self, stage: &str) -> Result<(), DenoiseError> {
        let mut msg: *const c_char = std::ptr::null();
        // SAFETY: `device` is live; the message is copied before any other OIDN call.
        let code = unsafe { (self.api.get_device_error)(self.device, &mut msg) };
        if code == 0 {
            return Ok(());
        }
        // SAFETY: OIDN returns null or a C string valid until its next call.
        let msg = unsafe { oidn::message(msg) };
        Err(DenoiseError::Device(format!(
            "{stage}: {msg} (error {code})"
        )))
    }

    /// A device buffer holding a copy of `values`.
    fn buffer(&self, values: &[f32]) -> Result<Handle, DenoiseError> {
        let bytes = std::mem::size_of_val(values);
        // SAFETY: `device` is live; the write reads `bytes` bytes from `values`, which holds
        // exactly that many, into a buffer of that size.
        let ptr = unsafe { (self.api.new_buffer)(self.device, bytes) };
        if ptr.is_null() {
            self.check("buffer allocation")?;
            return Err(DenoiseError::Device("buffer allocation failed".into()));
        }
        let h = Handle {
            ptr,
            release: self.api.release_buffer,
        };
        // SAFETY: see above.
        unsafe { (self.api.write_buffer)(ptr, 0, bytes, values.as_ptr().cast()) };
        self.check("buffer upload")?;
        Ok(h)
    }

    /// Creates an RT filter, lets `setup` bind its images and flags, commits and executes it.
    fn run(&self, stage: &str, setup: impl FnOnce(&Filter)) -> Result<(), DenoiseError> {
        // SAFETY: `device` is live; "RT" is a C string.
        let ptr = unsafe { (self.api.new_filter)(self.device, c"RT".as_ptr()) };
        if ptr.is_null() {
            self.check(stage)?;
            return Err(DenoiseError::Device(format!("{stage}: no RT filter")));
        }
        let filter = Filter {
            api: &self.api,
            handle: Handle {
                ptr,
                release: self.api.release_filter,
            },
        };
        setup(&filter);
        // SAFETY: the filter is live and its images are bound to live buffers.
        unsafe { (self.api.commit_filter)(ptr) };
        self.check(stage)?;
        // SAFETY: as above; execution is synchronous.
        unsafe { (self.api.execute_filter)(ptr) };
        self.check(stage)
    }

    /// Denoises `input.color`, guided by the albedo and normal images when given; with
    /// `prefilter` those are denoised first (see the module notes). Returns RGB interleaved,
    /// like the input. Non-finite or out-of-range input values are replaced (colour: by 0; albedo and normal: clamped to their ranges, non-finite by 0).
    pub fn denoise(&self, input: &Input, prefilter: bool) -> Result<Vec<f32>, DenoiseError> {
        input.check()?;
        let (w, h) = (input.width, input.height);
        let color = sanitized(input.color, Kind::Color);
        let albedo = input.albedo.map(|a| sanitized(a, Kind::Albedo));
        let normal = input.normal.map(|n| sanitized(n, Kind::Normal));
        let _serial = self.lock.lock().unwrap_or_else(|e| e.into_inner());
        // Drop any error left by an earlier failed call.
        let _ = self.check("");
        let color_buf = self.buffer(&color)?;
        let output = self.buffer(&vec![0.0; color.len()])?;
        let albedo_buf = albedo.as_deref().map(|a| self.buffer(a)).transpose()?;
        let normal_buf = normal.as_deref().map(|n| self.buffer(n)).transpose()?;
        if prefilter {
            for (name, buf) in [(c"albedo", &albedo_buf), (c"normal", &normal_buf)] {
                if let Some(buf) = buf {
                    let stage = format!("prefiltering the {} image", name.to_string_lossy());
                    self.run(&stage, |f| {
                        f.image(name, buf, w, h);
                        f.image(c"output", buf, w, h);
                    })?;
                }
            }
        }
        self.run("denoising", |f| {
            f.image(c"color", &color_buf, w, h);
            if let Some(b) = &albedo_buf {
                f.image(c"albedo", b, w, h);
            }
            if let Some(b) = &normal_buf {
                f.image(c"normal", b, w, h);
            }
            f.image(c"output", &output, w, h);
            f.flag(c"hdr", true);
            f.flag(c"cleanAux", prefilter && albedo_buf.is_some());
        })?;
        let mut out = vec![0.0f32; color.len()];
        // SAFETY: `output` holds exactly `size_of_val(out)` bytes and `out` has room for them.
        unsafe {
            (self.api.read_buffer)(
                output.ptr,
                0,
                std::mem::size_of_val(out.as_slice()),
                out.as_mut_ptr().cast(),
            )
        };
        self.check("reading the result")?;
        if let Some(i) = out.iter().position(|v| !v.is_finite()) {
            return Err(DenoiseError::Device(format!(
                "the result has a non-finite value at pixel {} (refused)",
                i / 3
            )));
        }
        Ok(out)
    }
}

/// A filter being set up inside [`Denoiser::run`].
struct Filter<'a> {
    api: &'a oidn::Api,
    handle: Handle,
}

impl Filter<'_> {
    /// Binds `buf` (packed `w × h` RGB f32) as image `name`.
    fn image(&self, name: &CStr, buf: &Handle, w: usize, h: usize) {
        // SAFETY: filter and buffer are live handles of the same device; strides 0 mean packed,
        // which matches how the buffers were filled; the buffer holds w·h·12 bytes.
        unsafe {
            (self.api.set_filter_image)(
                self.handle.ptr,
                name.as_ptr(),
                buf.ptr,
                oidn::FORMAT_FLOAT3,
                w,
                h,
                0,
                0,
                0,
            )
        };
    }

    fn flag(&self, name: &CStr, value: bool) {
        // SAFETY: the filter is live; `name` is a C string.
        unsafe { (self.api.set_filter_bool)(self.handle.ptr, name.as_ptr(), value) };
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sanitizing_replaces_non_finite_and_clamps_each_kind() {
        let v = [f32::NAN, f32::INFINITY, f32::NEG_INFINITY, -0.5, 0.25, 3.0];
        assert_eq!(sanitized(&v, Kind::Color), [0.0, 0.0, 0.0, 0.0, 0.25, 3.0]);
        assert_eq!(sanitized(&v, Kind::Albedo), [0.0, 0.0, 0.0, 0.0, 0.25, 1.0]);
        assert_eq!(
            sanitized(&v, Kind::Normal),
            [0.0, 0.0, 0.0, -0.5, 0.25, 1.0]
        );
    }
}
