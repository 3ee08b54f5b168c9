//! The part of OIDN 2's C API pathlight calls (`oidn.h`), bound at run time: a CPU device
//! and `RT` filters over images in host memory.

use std::ffi::{CStr, CString, c_char, c_int, c_void};
use std::path::Path;

use libloading::Library;

/// `OIDN_DEVICE_TYPE_CPU`.
const DEVICE_TYPE_CPU: c_int = 1;
/// `OIDN_FORMAT_FLOAT3`.
const FORMAT_FLOAT3: c_int = 3;
/// `OIDN_ERROR_NONE`.
const ERROR_NONE: c_int = 0;

/// `OIDNQuality`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Quality {
    /// `OIDN_QUALITY_BALANCED`.
    Balanced = 5,
    /// `OIDN_QUALITY_HIGH`.
    High = 6,
}

/// A filter's settings.
#[derive(Debug, Clone, Copy)]
pub struct Options {
    /// The input is HDR radiance (the beauty image), not an auxiliary image.
    hdr: bool,
    /// `cleanAux`: the auxiliary images are noise-free.
    clean_aux: bool,
    quality: Quality,
}

impl Options {
    /// For the beauty image (HDR), with auxiliary images that are noise-free (`clean_aux`)
    /// or not.
    pub fn beauty(clean_aux: bool, quality: Quality) -> Self {
        Self {
            hdr: true,
            clean_aux,
            quality,
        }
    }

    /// For denoising an auxiliary image on its own (prefiltering).
    pub fn auxiliary(quality: Quality) -> Self {
        Self {
            hdr: false,
            clean_aux: false,
            quality,
        }
    }
}

type NewDevice = unsafe extern "C" fn(c_int) -> *mut c_void;
type DeviceFn = unsafe extern "C" fn(*mut c_void);
type GetDeviceError = unsafe extern "C" fn(*mut c_void, *mut *const c_char) -> c_int;
type GetDeviceInt = unsafe extern "C" fn(*mut c_void, *const c_char) -> c_int;
type NewFilter = unsafe extern "C" fn(*mut c_void, *const c_char) -> *mut c_void;
type SetSharedFilterImage = unsafe extern "C" fn(
    *mut c_void,
    *const c_char,
    *mut c_void,
    c_int,
    usize,
    usize,
    usize,
    usize,
    usize,
);
type SetFilterBool = unsafe extern "C" fn(*mut c_void, *const c_char, bool);
type SetFilterInt = unsafe extern "C" fn(*mut c_void, *const c_char, c_int);
type FilterFn = unsafe extern "C" fn(*mut c_void);

/// The functions used, looked up once.
struct Api {
    commit_device: DeviceFn,
    get_device_error: GetDeviceError,
    get_device_int: GetDeviceInt,
    release_device: DeviceFn,
    new_filter: NewFilter,
    set_shared_filter_image: SetSharedFilterImage,
    set_filter_bool: SetFilterBool,
    set_filter_int: SetFilterInt,
    commit_filter: FilterFn,
    execute_filter: FilterFn,
    release_filter: FilterFn,
}

/// An OIDN CPU device and the library it came from (kept loaded while the device lives).
pub struct Device {
    api: Api,
    handle: *mut c_void,
    _library: Library,
}

// SAFETY: an OIDN device may be used from any thread; `Device` takes `&self` for filters,
// which OIDN allows on one device from one thread at a time, and it is not `Sync`.
unsafe impl Send for Device {}

/// The symbol `name` of `library` as a `T`.
///
/// # Safety
/// `T` must be the symbol's C signature.
unsafe fn symbol<T: Copy>(library: &Library, name: &str) -> Result<T, String> {
    // SAFETY: the caller gives the symbol's signature.
    unsafe { library.get::<T>(name.as_bytes()) }
        .map(|s| *s)
        .map_err(|err| format!("not Open Image Denoise 2 ({name}: {err})"))
}

impl Device {
    /// Loads the library at `path` (a file, or a name the system's loader finds) and opens
    /// a CPU device on it.
    pub fn open(path: &Path) -> Result<Self, String> {
        // SAFETY: loading runs the library's initialisers; OIDN's have no requirements.
        let library = unsafe { Library::new(path) }.map_err(|err| err.to_string())?;
        // SAFETY: each type is the function's signature in OIDN 2's `oidn.h`.
        let (api, new_device) = unsafe {
            (
                Api {
                    commit_device: symbol(&library, "oidnCommitDevice")?,
                    get_device_error: symbol(&library, "oidnGetDeviceError")?,
                    get_device_int: symbol(&library, "oidnGetDeviceInt")?,
                    release_device: symbol(&library, "oidnReleaseDevice")?,
                    new_filter: symbol(&library, "oidnNewFilter")?,
                    set_shared_filter_image: symbol(&library, "oidnSetSharedFilterImage")?,
                    set_filter_bool: symbol(&library, "oidnSetFilterBool")?,
                    set_filter_int: symbol(&library, "oidnSetFilterInt")?,
                    commit_filter: symbol(&library, "oidnCommitFilter")?,
                    execute_filter: symbol(&library, "oidnExecuteFilter")?,
                    release_filter: symbol(&library, "oidnReleaseFilter")?,
                },
                symbol::<NewDevice>(&library, "oidnNewDevice")?,
            )
        };
        // SAFETY: a C call with a valid device type.
        let handle = unsafe { new_device(DEVICE_TYPE_CPU) };
        if handle.is_null() {
            return Err("it opened no CPU device (is its CPU module beside it?)".into());
        }
        let device = Self {
            api,
            handle,
            _library: library,
        };
        // SAFETY: the device is valid.
        unsafe { (device.api.commit_device)(device.handle) };
        device.check()?;
        let major = device.int("versionMajor");
        if major != 2 {
            return Err(format!(
                "Open Image Denoise {major}.x; pathlight needs version 2"
            ));
        }
        Ok(device)
    }

    /// The device's integer parameter `name`.
    fn int(&self, name: &str) -> i32 {
        let name = CString::new(name).expect("no NUL in a parameter name");
        // SAFETY: the device and the name are valid.
        unsafe { (self.api.get_device_int)(self.handle, name.as_ptr()) }
    }

    /// OIDN's version, `major.minor.patch`.
    pub fn version(&self) -> String {
        format!(
            "{}.{}.{}",
            self.int("versionMajor"),
            self.int("versionMinor"),
            self.int("versionPatch")
        )
    }

    /// The device's first error since the last check, if any.
    fn check(&self) -> Result<(), String> {
        let mut message: *const c_char = std::ptr::null();
        // SAFETY: the device is valid; the message lives until the next OIDN call.
        let code = unsafe { (self.api.get_device_error)(self.handle, &mut message) };
        if code == ERROR_NONE {
            return Ok(());
        }
        let text = if message.is_null() {
            String::new()
        } else {
            // SAFETY: OIDN returns a NUL-terminated string.
            unsafe { CStr::from_ptr(message) }
                .to_string_lossy()
                .into_owned()
        };
        Err(format!("error {code}: {text}"))
    }

    /// Runs an `RT` filter over `width` x `height` images: the named `inputs` (`color`,
    /// `albedo`, `normal`) into `output`.
    pub fn filter(
        &self,
        width: usize,
        height: usize,
        inputs: &[(&str, &[[f32; 3]])],
        output: &mut [[f32; 3]],
        options: Options,
    ) -> Result<(), String> {
        let pixels = width * height;
        assert!(
            inputs.iter().all(|(_, image)| image.len() == pixels) && output.len() == pixels,
            "every image holds width x height pixels"
        );
        let rt = CString::new("RT").expect("no NUL");
        // SAFETY: the device is valid.
        let filter = unsafe { (self.api.new_filter)(self.handle, rt.as_ptr()) };
        self.check()?;
        let set_image = |name: &str, data: *mut c_void| {
            let name = CString::new(name).expect("no NUL in an image name");
            // SAFETY: `data` holds `pixels` packed float triples that outlive the filter's
            // execution (OIDN only reads inputs and writes the output).
            unsafe {
                (self.api.set_shared_filter_image)(
                    filter,
                    name.as_ptr(),
                    data,
                    FORMAT_FLOAT3,
                    width,
                    height,
                    0,
                    0,
                    0,
                );
            }
        };
        for (name, image) in inputs {
            set_image(name, image.as_ptr() as *mut c_void);
        }
        set_image("output", output.as_mut_ptr() as *mut c_void);
        let flag = |name: &str, value: bool| {
            let name = CString::new(name).expect("no NUL");
            // SAFETY: the filter and the name are valid.
            unsafe { (self.api.set_filter_bool)(filter, name.as_ptr(), value) };
        };
        flag("hdr", options.hdr);
        flag("cleanAux", options.clean_aux);
        let quality = CString::new("quality").expect("no NUL");
        // SAFETY: the filter and the name are valid.
        unsafe {
            (self.api.set_filter_int)(filter, quality.as_ptr(), options.quality as c_int);
            (self.api.commit_filter)(filter);
            (self.api.execute_filter)(filter);
            (self.api.release_filter)(filter);
        }
        self.check()
    }
}

impl Drop for Device {
    fn drop(&mut self) {
        // SAFETY: the device is valid and released once.
        unsafe { (self.api.release_device)(self.handle) };
    }
}
