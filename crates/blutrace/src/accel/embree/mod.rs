//! Intel Embree 4 backend, loaded at run time (no build-time link, no C toolchain).
//!
//! A thin FFI of our own: only the calls and structs used here are declared, checked
//! against Embree 4.4's headers (`include/embree4/rtcore_{ray,device,scene,geometry,
//! buffer,common}.h`). The layouts that matter:
//!
//! | struct      | size | fields (byte offset)                                                  |
//! |-------------|------|-----------------------------------------------------------------------|
//! | `RTCRay`    | 48   | org_xyz 0, tnear 12, dir_xyz 16, time 28, tfar 32, mask 36, id 40, flags 44 (align 16) |
//! | `RTCHit`    | 48   | Ng_xyz 0, u 12, v 16, primID 20, geomID 24, instID\[1\] 28, instPrimID\[1\] 32 (align 16) |
//! | `RTCRayHit` | 96   | ray 0, hit 48                                                         |
//! | `RTCRayHitN` | 84 N | SoA packets of N = 4, 8, 16 rays ([`packet`]): `RTCRayN` then `RTCHitN`, every field an array of N lanes |
//!
//! `instPrimID` arrived with instance arrays in Embree 4.3 (`RTC_GEOMETRY_INSTANCE_ARRAY`,
//! on in release builds); a 4.2-era declaration (`embree4-sys` 0.0.12: 80-byte
//! `RTCRayHit`) lets 4.4 write past the struct. The library's major.minor is therefore
//! checked at start-up and anything but 4.4 is refused. `RTCIntersectArguments` is not
//! declared: `rtcIntersect1` is always passed a null `args` (its layout depends on
//! `RTC_MIN_WIDTH`, a build option).
//!
//! Where the library is found, first match wins:
//! 1. env `BLUTRACE_EMBREE`: the `.so` itself or a folder holding `libembree4.so.4`
//!    (when set, nothing else is tried);
//! 2. the folder `tools/fetch-embree.sh` fills, `<crate>/third_party/embree/lib`
//!    (baked in by `build.rs`);
//! 3. the system's `libembree4.so.4` (the dynamic loader's search path).
//!
//! Embree works in f32: the distance it reports is refined in f64 by the shared code
//! ([`crate::geometry::Facet::refine_hit`]), and rays leaving a surface start
//! [`crate::geometry::spawn_epsilon`] off it, so the f32 test never re-hits the surface a
//! ray leaves. The scene is built with
//! `RTC_SCENE_FLAG_ROBUST` (watertight triangle test: no leaks through shared edges) and
//! high build quality (scenes are built once and traced millions of times).
//!
//! [`EmbreeAccel::intersect_packet`] traces packets of 4, 8 or 16 rays
//! (`rtcIntersect4/8/16`); `blutrace bench` measures whether they pay for photon rays.

pub mod packet;

use super::{Accel, Hit};
use crate::geometry::{Mesh, Ray};
use anyhow::{Result, anyhow, bail};
use libloading::Library;
use std::ffi::{CString, c_uint};
use std::path::{Path, PathBuf};
use std::ptr;
use std::sync::{Arc, OnceLock};

/// Env var naming the Embree library (a `.so` file or a folder holding `libembree4.so.4`).
pub const ENV_LIBRARY: &str = "BLUTRACE_EMBREE";

/// File name of the library in a folder, and the soname looked up on the system.
const LIBRARY_NAME: &str = "libembree4.so.4";

/// The folder `tools/fetch-embree.sh` installs into (set by `build.rs`).
const DEFAULT_DIR: Option<&str> = option_env!("BLUTRACE_EMBREE_DEFAULT_DIR");

/// The one Embree (major, minor) whose ABI this module declares.
const SUPPORTED_VERSION: (isize, isize) = (4, 4);

/// What to tell a user whose Embree could not be used.
const HOW_TO_GET_IT: &str = "run `bash tools/fetch-embree.sh` (installs Embree 4.4.0 into \
     third_party/embree/lib), or set BLUTRACE_EMBREE to a libembree4.so.4 of Embree 4.4 or \
     to its folder";

/// The Embree 4 C API subset, as in the 4.4 headers.
#[allow(non_camel_case_types, non_snake_case, clippy::upper_case_acronyms)]
mod ffi {
    use std::ffi::{c_char, c_uint, c_void};
    use std::mem::{align_of, offset_of, size_of};

    /// Opaque `RTCDevice` (`struct RTCDeviceTy*`).
    pub type RTCDevice = *mut c_void;
    /// Opaque `RTCScene`.
    pub type RTCScene = *mut c_void;
    /// Opaque `RTCGeometry`.
    pub type RTCGeometry = *mut c_void;

    // rtcore_common.h
    pub const RTC_INVALID_GEOMETRY_ID: c_uint = u32::MAX;
    pub const RTC_FORMAT_UINT3: c_uint = 0x5003;
    pub const RTC_FORMAT_FLOAT3: c_uint = 0x9003;
    pub const RTC_BUILD_QUALITY_HIGH: c_uint = 2;
    // rtcore_device.h: enum RTCDeviceProperty
    pub const RTC_DEVICE_PROPERTY_VERSION: c_uint = 0;
    pub const RTC_DEVICE_PROPERTY_VERSION_MAJOR: c_uint = 1;
    pub const RTC_DEVICE_PROPERTY_VERSION_MINOR: c_uint = 2;
    pub const RTC_DEVICE_PROPERTY_VERSION_PATCH: c_uint = 3;
    pub const RTC_DEVICE_PROPERTY_NATIVE_RAY4_SUPPORTED: c_uint = 32;
    pub const RTC_DEVICE_PROPERTY_NATIVE_RAY8_SUPPORTED: c_uint = 33;
    pub const RTC_DEVICE_PROPERTY_NATIVE_RAY16_SUPPORTED: c_uint = 34;
    pub const RTC_DEVICE_PROPERTY_BACKFACE_CULLING_ENABLED: c_uint = 65;
    pub const RTC_DEVICE_PROPERTY_TRIANGLE_GEOMETRY_SUPPORTED: c_uint = 96;
    // rtcore_device.h: enum RTCError
    pub const RTC_ERROR_NONE: c_uint = 0;
    // rtcore_scene.h: enum RTCSceneFlags
    pub const RTC_SCENE_FLAG_ROBUST: c_uint = 1 << 2;
    // rtcore_geometry.h: enum RTCGeometryType
    pub const RTC_GEOMETRY_TYPE_TRIANGLE: c_uint = 0;
    // rtcore_buffer.h: enum RTCBufferType
    pub const RTC_BUFFER_TYPE_INDEX: c_uint = 0;
    pub const RTC_BUFFER_TYPE_VERTEX: c_uint = 1;

    /// `RTC_MAX_INSTANCE_LEVEL_COUNT` of release builds.
    pub const MAX_INSTANCE_LEVEL_COUNT: usize = 1;

    /// `struct RTC_ALIGN(16) RTCRay` (rtcore_ray.h).
    #[repr(C, align(16))]
    #[derive(Clone, Copy, Debug)]
    pub struct RTCRay {
        pub org_x: f32,
        pub org_y: f32,
        pub org_z: f32,
        pub tnear: f32,
        pub dir_x: f32,
        pub dir_y: f32,
        pub dir_z: f32,
        pub time: f32,
        pub tfar: f32,
        pub mask: c_uint,
        pub id: c_uint,
        pub flags: c_uint,
    }

    /// `struct RTC_ALIGN(16) RTCHit` (rtcore_ray.h, with `RTC_GEOMETRY_INSTANCE_ARRAY`).
    #[repr(C, align(16))]
    #[derive(Clone, Copy, Debug)]
    pub struct RTCHit {
        pub Ng_x: f32,
        pub Ng_y: f32,
        pub Ng_z: f32,
        pub u: f32,
        pub v: f32,
        pub primID: c_uint,
        pub geomID: c_uint,
        pub instID: [c_uint; MAX_INSTANCE_LEVEL_COUNT],
        pub instPrimID: [c_uint; MAX_INSTANCE_LEVEL_COUNT],
    }

    /// `struct RTCRayHit` (rtcore_ray.h); 16-aligned through its members.
    #[repr(C)]
    #[derive(Clone, Copy, Debug)]
    pub struct RTCRayHit {
        pub ray: RTCRay,
        pub hit: RTCHit,
    }

    const _: () = {
        assert!(size_of::<RTCRay>() == 48 && align_of::<RTCRay>() == 16);
        assert!(offset_of!(RTCRay, tnear) == 12);
        assert!(offset_of!(RTCRay, dir_x) == 16);
        assert!(offset_of!(RTCRay, time) == 28);
        assert!(offset_of!(RTCRay, tfar) == 32);
        assert!(offset_of!(RTCRay, mask) == 36);
        assert!(offset_of!(RTCRay, flags) == 44);
        assert!(size_of::<RTCHit>() == 48 && align_of::<RTCHit>() == 16);
        assert!(offset_of!(RTCHit, u) == 12);
        assert!(offset_of!(RTCHit, primID) == 20);
        assert!(offset_of!(RTCHit, geomID) == 24);
        assert!(offset_of!(RTCHit, instID) == 28);
        assert!(offset_of!(RTCHit, instPrimID) == 32);
        assert!(size_of::<RTCRayHit>() == 96 && align_of::<RTCRayHit>() == 16);
        assert!(offset_of!(RTCRayHit, hit) == 48);
    };

    pub type NewDevice = unsafe extern "C" fn(config: *const c_char) -> RTCDevice;
    pub type GetDeviceProperty = unsafe extern "C" fn(RTCDevice, prop: c_uint) -> isize;
    pub type GetDeviceError = unsafe extern "C" fn(RTCDevice) -> c_uint;
    pub type ReleaseDevice = unsafe extern "C" fn(RTCDevice);
    pub type NewScene = unsafe extern "C" fn(RTCDevice) -> RTCScene;
    pub type SetSceneFlags = unsafe extern "C" fn(RTCScene, flags: c_uint);
    pub type SetSceneBuildQuality = unsafe extern "C" fn(RTCScene, quality: c_uint);
    pub type NewGeometry = unsafe extern "C" fn(RTCDevice, kind: c_uint) -> RTCGeometry;
    pub type SetNewGeometryBuffer = unsafe extern "C" fn(
        RTCGeometry,
        kind: c_uint,
        slot: c_uint,
        format: c_uint,
        byte_stride: usize,
        item_count: usize,
    ) -> *mut c_void;
    pub type CommitGeometry = unsafe extern "C" fn(RTCGeometry);
    pub type AttachGeometry = unsafe extern "C" fn(RTCScene, RTCGeometry) -> c_uint;
    pub type ReleaseGeometry = unsafe extern "C" fn(RTCGeometry);
    pub type CommitScene = unsafe extern "C" fn(RTCScene);
    /// `rtcIntersect1(scene, rayhit, args)`; `args` (`RTCIntersectArguments*`) may be null.
    pub type Intersect1 = unsafe extern "C" fn(RTCScene, *mut RTCRayHit, args: *mut c_void);
    pub type ReleaseScene = unsafe extern "C" fn(RTCScene);
    /// `rtcIntersect4/8/16(valid, scene, rayhit, args)`: `valid` (N `int`s, -1 active, 0
    /// not) and `rayhit` (`RTCRayHitN*`) aligned to 4 N bytes; `args` may be null.
    pub type IntersectN =
        unsafe extern "C" fn(valid: *const i32, RTCScene, rayhit: *mut c_void, args: *mut c_void);

    /// `enum RTCError` names.
    pub(super) fn error_name(code: c_uint) -> &'static str {
        match code {
            0 => "RTC_ERROR_NONE",
            1 => "RTC_ERROR_UNKNOWN",
            2 => "RTC_ERROR_INVALID_ARGUMENT",
            3 => "RTC_ERROR_INVALID_OPERATION",
            4 => "RTC_ERROR_OUT_OF_MEMORY",
            5 => "RTC_ERROR_UNSUPPORTED_CPU",
            6 => "RTC_ERROR_CANCELLED",
            7 => "RTC_ERROR_LEVEL_ZERO_RAYTRACING_SUPPORT_MISSING",
            _ => "unknown RTCError",
        }
    }
}

use ffi::*;

/// The loaded library and its entry points. Lives for the whole process (never unloaded:
/// TBB does not like being torn down under running threads).
struct Api {
    path: PathBuf,
    version: String,
    new_device: NewDevice,
    get_device_property: GetDeviceProperty,
    get_device_error: GetDeviceError,
    release_device: ReleaseDevice,
    new_scene: NewScene,
    set_scene_flags: SetSceneFlags,
    set_scene_build_quality: SetSceneBuildQuality,
    new_geometry: NewGeometry,
    set_new_geometry_buffer: SetNewGeometryBuffer,
    commit_geometry: CommitGeometry,
    attach_geometry: AttachGeometry,
    release_geometry: ReleaseGeometry,
    commit_scene: CommitScene,
    intersect1: Intersect1,
    /// `rtcIntersect4`, `rtcIntersect8`, `rtcIntersect16`.
    intersect_n: [IntersectN; 3],
    release_scene: ReleaseScene,
    _lib: Library,
}

/// Facts about the Embree library in use.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct EmbreeInfo {
    /// The library file (or system soname) that was loaded.
    pub path: PathBuf,
    /// Its version, e.g. "4.4.0".
    pub version: String,
}

/// Load Embree (once per process) and report which library and version is used; the
/// error says what was tried and how to get the library.
pub fn info() -> Result<EmbreeInfo> {
    let api = api()?;
    Ok(EmbreeInfo {
        path: api.path.clone(),
        version: api.version.clone(),
    })
}

fn api() -> Result<&'static Api> {
    static API: OnceLock<Result<Api, String>> = OnceLock::new();
    API.get_or_init(load).as_ref().map_err(|e| anyhow!("{e}"))
}

/// The libraries to try, in order, with where each came from.
fn candidates() -> Vec<(PathBuf, String)> {
    if let Some(v) = std::env::var_os(ENV_LIBRARY).filter(|v| !v.is_empty()) {
        let p = PathBuf::from(v);
        let p = if p.is_dir() { p.join(LIBRARY_NAME) } else { p };
        return vec![(p, format!("from ${ENV_LIBRARY}"))];
    }
    let mut list = Vec::new();
    if let Some(dir) = DEFAULT_DIR {
        let p = Path::new(dir).join(LIBRARY_NAME);
        list.push((p, "fetched by tools/fetch-embree.sh".to_string()));
    }
    list.push((PathBuf::from(LIBRARY_NAME), "system".to_string()));
    list
}

fn load() -> Result<Api, String> {
    let mut tried = Vec::new();
    for (path, origin) in candidates() {
        let has_folder = path.parent().is_some_and(|p| !p.as_os_str().is_empty());
        if has_folder && !path.exists() {
            tried.push(format!("{} ({origin}): not present", path.display()));
            continue;
        }
        match load_from(&path) {
            Ok(api) => return Ok(api),
            Err(e) => tried.push(format!("{} ({origin}): {e:#}", path.display())),
        }
    }
    Err(format!(
        "Embree {}.{} is not available: tried {}. To use it, {HOW_TO_GET_IT}",
        SUPPORTED_VERSION.0,
        SUPPORTED_VERSION.1,
        tried.join("; ")
    ))
}

/// Look up `name` in `lib` as a value of type `T` (a function pointer type).
///
/// # Safety
/// `T` must be the symbol's true type, and the pointer must not outlive `lib`.
unsafe fn symbol<T: Copy>(lib: &Library, name: &str) -> Result<T> {
    // SAFETY: forwarded to the caller.
    let sym = unsafe { lib.get::<T>(name.as_bytes()) }
        .map_err(|e| anyhow::Error::new(e).context(format!("symbol {name} missing")))?;
    Ok(*sym)
}

fn load_from(path: &Path) -> Result<Api> {
    // SAFETY: loading runs the library's initialisers; Embree's and TBB's are benign.
    let lib = unsafe { Library::new(path.as_os_str()) }.map_err(anyhow::Error::new)?;
    // SAFETY: each type below is the prototype from the Embree 4.4 headers; the pointers
    // live in `Api` next to the `Library` that keeps them valid, and `Api` is never dropped
    // (it sits in a static).
    let mut api = unsafe {
        Api {
            path: path.to_path_buf(),
            version: String::new(),
            new_device: symbol(&lib, "rtcNewDevice")?,
            get_device_property: symbol(&lib, "rtcGetDeviceProperty")?,
            get_device_error: symbol(&lib, "rtcGetDeviceError")?,
            release_device: symbol(&lib, "rtcReleaseDevice")?,
            new_scene: symbol(&lib, "rtcNewScene")?,
            set_scene_flags: symbol(&lib, "rtcSetSceneFlags")?,
            set_scene_build_quality: symbol(&lib, "rtcSetSceneBuildQuality")?,
            new_geometry: symbol(&lib, "rtcNewGeometry")?,
            set_new_geometry_buffer: symbol(&lib, "rtcSetNewGeometryBuffer")?,
            commit_geometry: symbol(&lib, "rtcCommitGeometry")?,
            attach_geometry: symbol(&lib, "rtcAttachGeometry")?,
            release_geometry: symbol(&lib, "rtcReleaseGeometry")?,
            commit_scene: symbol(&lib, "rtcCommitScene")?,
            intersect1: symbol(&lib, "rtcIntersect1")?,
            intersect_n: [
                symbol(&lib, "rtcIntersect4")?,
                symbol(&lib, "rtcIntersect8")?,
                symbol(&lib, "rtcIntersect16")?,
            ],
            release_scene: symbol(&lib, "rtcReleaseScene")?,
            _lib: lib,
        }
    };
    // A throw-away device to read the version before any struct crosses the boundary.
    let version = Device::new(&api, 1).and_then(|device| device.check_version());
    match version {
        Ok(v) => {
            api.version = v;
            Ok(api)
        }
        Err(e) => {
            // Keep a refused library mapped: unloading a library that may have started
            // TBB worker threads is not safe.
            std::mem::forget(api);
            Err(e)
        }
    }
}

/// An owned `RTCDevice`.
struct Device<'a> {
    api: &'a Api,
    raw: RTCDevice,
}

impl<'a> Device<'a> {
    fn new(api: &'a Api, threads: usize) -> Result<Self> {
        let config = CString::new(format!("threads={}", threads.max(1))).expect("no NUL");
        // SAFETY: a valid NUL-terminated config string.
        let raw = unsafe { (api.new_device)(config.as_ptr()) };
        if raw.is_null() {
            // SAFETY: a null device asks for the thread's device-creation error.
            let code = unsafe { (api.get_device_error)(ptr::null_mut()) };
            bail!("rtcNewDevice failed: {}", error_name(code));
        }
        Ok(Self { api, raw })
    }

    fn property(&self, prop: c_uint) -> isize {
        // SAFETY: a live device and a property from the header.
        unsafe { (self.api.get_device_property)(self.raw, prop) }
    }

    /// Fails with the device's pending error, if any, naming `what` was done.
    fn check(&self, what: &str) -> Result<()> {
        // SAFETY: a live device.
        let code = unsafe { (self.api.get_device_error)(self.raw) };
        if code == RTC_ERROR_NONE {
            Ok(())
        } else {
            bail!("Embree {what} failed: {}", error_name(code))
        }
    }

    /// The library's version, if its major.minor is the one declared here and it traces
    /// triangles two-sided.
    fn check_version(&self) -> Result<String> {
        let major = self.property(RTC_DEVICE_PROPERTY_VERSION_MAJOR);
        let minor = self.property(RTC_DEVICE_PROPERTY_VERSION_MINOR);
        let patch = self.property(RTC_DEVICE_PROPERTY_VERSION_PATCH);
        let number = self.property(RTC_DEVICE_PROPERTY_VERSION);
        self.check("rtcGetDeviceProperty(VERSION)")?;
        let version = format!("{major}.{minor}.{patch}");
        if (major, minor) != SUPPORTED_VERSION || number / 100 != major * 100 + minor {
            bail!(
                "it is Embree {version} (RTC_DEVICE_PROPERTY_VERSION {number}), but blutrace \
                 declares the Embree {}.{} ABI (RTCRayHit layout) and refuses other major/minor \
                 versions",
                SUPPORTED_VERSION.0,
                SUPPORTED_VERSION.1
            );
        }
        if self.property(RTC_DEVICE_PROPERTY_TRIANGLE_GEOMETRY_SUPPORTED) != 1 {
            bail!("this Embree {version} build has no triangle geometry");
        }
        if self.property(RTC_DEVICE_PROPERTY_BACKFACE_CULLING_ENABLED) != 0 {
            bail!("this Embree {version} build culls back faces; blutrace needs two-sided hits");
        }
        Ok(version)
    }
}

impl Drop for Device<'_> {
    fn drop(&mut self) {
        // SAFETY: we own one reference to the device.
        unsafe { (self.api.release_device)(self.raw) }
    }
}

/// Releases a geometry handle on every path out of [`EmbreeAccel::new`].
struct GeometryRef<'a>(&'a Api, RTCGeometry);

impl Drop for GeometryRef<'_> {
    fn drop(&mut self) {
        // SAFETY: we own one reference to the geometry.
        unsafe { (self.0.release_geometry)(self.1) }
    }
}

/// Embree BVH over the scene mesh: one triangle geometry whose primIDs are the mesh's
/// triangle indices.
pub struct EmbreeAccel {
    // Field order is drop order: the scene is released before its device.
    scene: Scene,
    device: Device<'static>,
    triangles: u32,
}

/// An owned, committed `RTCScene`.
struct Scene {
    api: &'static Api,
    raw: RTCScene,
}

impl Drop for Scene {
    fn drop(&mut self) {
        // SAFETY: we own one reference to the scene.
        unsafe { (self.api.release_scene)(self.raw) }
    }
}

// SAFETY: after `rtcCommitScene` the scene is never modified; Embree documents ray queries
// on a committed scene as thread-safe, and releasing happens once, in `Drop`, with `&mut`.
unsafe impl Send for EmbreeAccel {}
// SAFETY: as above: `intersect` only calls the thread-safe `rtcIntersect1`.
unsafe impl Sync for EmbreeAccel {}

impl EmbreeAccel {
    /// Load Embree (if not yet loaded) and build its BVH over `mesh`. The device uses as
    /// many threads as the current rayon pool.
    pub fn new(mesh: Arc<Mesh>) -> Result<Self> {
        let api = api()?;
        let triangles = u32::try_from(mesh.len())
            .map_err(|_| anyhow!("{} triangles exceed Embree's u32 primIDs", mesh.len()))?;
        let vertices = mesh.positions.len();
        if let Some((i, t)) = mesh
            .triangles
            .iter()
            .enumerate()
            .find(|(_, t)| t.iter().any(|&v| v as usize >= vertices))
        {
            bail!("triangle {i} {t:?} indexes past the {vertices} vertices");
        }

        let device = Device::new(api, rayon::current_num_threads())?;
        // SAFETY: a live device.
        let raw = unsafe { (api.new_scene)(device.raw) };
        device.check("rtcNewScene")?;
        if raw.is_null() {
            bail!("rtcNewScene returned null");
        }
        let scene = Scene { api, raw };
        // SAFETY: a live scene; flags and quality are values of their header enums.
        unsafe {
            (api.set_scene_flags)(scene.raw, RTC_SCENE_FLAG_ROBUST);
            (api.set_scene_build_quality)(scene.raw, RTC_BUILD_QUALITY_HIGH);
        }
        device.check("scene set-up")?;

        if triangles > 0 {
            // SAFETY: a live device and a header geometry type.
            let geom = unsafe { (api.new_geometry)(device.raw, RTC_GEOMETRY_TYPE_TRIANGLE) };
            device.check("rtcNewGeometry(TRIANGLE)")?;
            if geom.is_null() {
                bail!("rtcNewGeometry returned null");
            }
            let geom = GeometryRef(api, geom);
            // SAFETY: Embree allocates `vertices` items of 12 bytes (padded for its 16-byte
            // loads), aligned to at least 16; we fill exactly those items.
            let vb = unsafe {
                (api.set_new_geometry_buffer)(
                    geom.1,
                    RTC_BUFFER_TYPE_VERTEX,
                    0,
                    RTC_FORMAT_FLOAT3,
                    12,
                    vertices,
                )
            };
            device.check("rtcSetNewGeometryBuffer(VERTEX, FLOAT3)")?;
            if vb.is_null() {
                bail!("rtcSetNewGeometryBuffer(VERTEX) returned null");
            }
            // SAFETY: see above; `[f32; 3]` is 12 bytes with alignment 4.
            let vb = unsafe { std::slice::from_raw_parts_mut(vb as *mut [f32; 3], vertices) };
            for (dst, p) in vb.iter_mut().zip(&mesh.positions) {
                *dst = p.as_vec3().to_array();
            }
            // SAFETY: as for the vertex buffer, `triangles` items of three u32.
            let ib = unsafe {
                (api.set_new_geometry_buffer)(
                    geom.1,
                    RTC_BUFFER_TYPE_INDEX,
                    0,
                    RTC_FORMAT_UINT3,
                    12,
                    triangles as usize,
                )
            };
            device.check("rtcSetNewGeometryBuffer(INDEX, UINT3)")?;
            if ib.is_null() {
                bail!("rtcSetNewGeometryBuffer(INDEX) returned null");
            }
            // SAFETY: see above; indices were checked against the vertex count.
            let ib =
                unsafe { std::slice::from_raw_parts_mut(ib as *mut [u32; 3], triangles as usize) };
            ib.copy_from_slice(&mesh.triangles);
            // SAFETY: a live geometry with both buffers set, attached to a live scene.
            let id = unsafe {
                (api.commit_geometry)(geom.1);
                (api.attach_geometry)(scene.raw, geom.1)
            };
            device.check("rtcCommitGeometry/rtcAttachGeometry")?;
            if id != 0 {
                bail!("rtcAttachGeometry gave geomID {id}, expected 0");
            }
            // `geom` drops here: the scene holds its own reference.
        }
        // SAFETY: a live scene whose geometry is committed.
        unsafe { (api.commit_scene)(scene.raw) };
        device.check("rtcCommitScene")?;
        Ok(Self {
            scene,
            device,
            triangles,
        })
    }

    /// The library in use.
    pub fn info(&self) -> EmbreeInfo {
        EmbreeInfo {
            path: self.device.api.path.clone(),
            version: self.device.api.version.clone(),
        }
    }

    /// The ray/hit record for `ray` on `[0, tmax]`, before the query.
    fn ray_hit(ray: &Ray, tmax: f64) -> RTCRayHit {
        let o = ray.origin.as_vec3();
        let d = ray.dir.as_vec3();
        RTCRayHit {
            ray: RTCRay {
                org_x: o.x,
                org_y: o.y,
                org_z: o.z,
                tnear: 0.0,
                dir_x: d.x,
                dir_y: d.y,
                dir_z: d.z,
                time: 0.0,
                // f64::INFINITY (and anything past f32::MAX) becomes f32::INFINITY.
                tfar: if tmax.is_finite() {
                    tmax as f32
                } else {
                    f32::INFINITY
                },
                mask: u32::MAX,
                id: 0,
                flags: 0,
            },
            hit: RTCHit {
                Ng_x: 0.0,
                Ng_y: 0.0,
                Ng_z: 0.0,
                u: 0.0,
                v: 0.0,
                primID: RTC_INVALID_GEOMETRY_ID,
                geomID: RTC_INVALID_GEOMETRY_ID,
                instID: [RTC_INVALID_GEOMETRY_ID; MAX_INSTANCE_LEVEL_COUNT],
                instPrimID: [RTC_INVALID_GEOMETRY_ID; MAX_INSTANCE_LEVEL_COUNT],
            },
        }
    }

    /// Runs `rtcIntersect1` on `rh`.
    ///
    /// # Safety
    /// `rh` must point to a writable, 16-aligned record of at least `size_of::<RTCRayHit>()`
    /// bytes with a valid ray.
    unsafe fn intersect_raw(&self, rh: *mut RTCRayHit) {
        // SAFETY: a committed scene (thread-safe queries); null args are allowed; the
        // record's validity is the caller's promise.
        unsafe { (self.device.api.intersect1)(self.scene.raw, rh, ptr::null_mut()) }
    }
}

impl Accel for EmbreeAccel {
    fn name(&self) -> &'static str {
        "embree"
    }

    fn intersect(&self, ray: &Ray, tmax: f64) -> Option<Hit> {
        // Embree needs 0 <= tnear <= tfar; an empty or NaN segment hits nothing.
        if tmax.is_nan() || tmax <= 0.0 {
            return None;
        }
        let mut rh = Self::ray_hit(ray, tmax);
        // SAFETY: a local, aligned, fully initialised record.
        unsafe { self.intersect_raw(&mut rh) };
        if rh.hit.geomID == RTC_INVALID_GEOMETRY_ID {
            return None;
        }
        debug_assert!(rh.hit.geomID == 0 && rh.hit.primID < self.triangles);
        Some(Hit {
            t: f64::from(rh.ray.tfar),
            prim: rh.hit.primID,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DVec3;

    /// Like the integration tests: no Embree is a failure unless the machine opts out.
    /// (Also the packet tests'.)
    pub(super) fn accel(mesh: Mesh) -> Option<EmbreeAccel> {
        if std::env::var("BLUTRACE_SKIP_EMBREE").is_ok_and(|v| v == "1") {
            eprintln!("BLUTRACE_SKIP_EMBREE=1: Embree test skipped");
            return None;
        }
        Some(EmbreeAccel::new(Arc::new(mesh)).unwrap_or_else(|e| panic!("{e:#}")))
    }

    fn unit_triangle() -> Mesh {
        Mesh {
            positions: vec![DVec3::ZERO, DVec3::X, DVec3::Y],
            triangles: vec![[0, 1, 2]],
            tri_tag: vec![0],
        }
    }

    /// The library writes nothing past our 96-byte `RTCRayHit`, and what it writes at
    /// `instPrimID` (the field 4.2-era declarations lack) is its "invalid" marker.
    #[test]
    fn library_writes_within_our_rayhit() {
        let Some(accel) = accel(unit_triangle()) else {
            return;
        };
        #[repr(C)]
        struct Guarded {
            rh: RTCRayHit,
            guard: [u32; 16],
        }
        const MARK: u32 = 0x5EED_1234;
        let ray = Ray::new(DVec3::new(0.25, 0.25, 2.0), DVec3::NEG_Z);
        let mut g = Guarded {
            rh: EmbreeAccel::ray_hit(&ray, f64::INFINITY),
            guard: [0xDEAD_BEEF; 16],
        };
        g.rh.hit.instPrimID = [MARK];
        // SAFETY: a local, aligned record with room to spare.
        unsafe { accel.intersect_raw(&mut g.rh) };
        assert_eq!((g.rh.hit.geomID, g.rh.hit.primID), (0, 0));
        assert!((g.rh.ray.tfar - 2.0).abs() < 1e-6);
        assert!(
            g.guard.iter().all(|&w| w == 0xDEAD_BEEF),
            "wrote past RTCRayHit"
        );
        let ipid = g.rh.hit.instPrimID[0];
        assert!(ipid == MARK || ipid == RTC_INVALID_GEOMETRY_ID, "{ipid:#x}");
        eprintln!(
            "Embree {} {} instPrimID",
            accel.info().version,
            if ipid == MARK { "leaves" } else { "writes" }
        );
    }

    #[test]
    fn hits_misses_and_respects_tmax() {
        let Some(accel) = accel(unit_triangle()) else {
            return;
        };
        assert_eq!(accel.name(), "embree");
        let down = Ray::new(DVec3::new(0.2, 0.2, 1.0), DVec3::NEG_Z);
        let hit = accel.intersect(&down, f64::INFINITY).expect("hit");
        assert_eq!(hit.prim, 0);
        assert!((hit.t - 1.0).abs() < 1e-6);
        assert_eq!(accel.intersect(&down, 0.5), None);
        assert_eq!(accel.intersect(&down, 0.0), None);
        assert_eq!(accel.intersect(&down, f64::NAN), None);
        let up = Ray::new(DVec3::new(0.2, 0.2, -1.0), DVec3::Z);
        assert_eq!(accel.intersect(&up, f64::INFINITY).map(|h| h.prim), Some(0));
        let outside = Ray::new(DVec3::new(0.8, 0.8, 1.0), DVec3::NEG_Z);
        assert_eq!(accel.intersect(&outside, f64::INFINITY), None);
    }

    #[test]
    fn empty_mesh_hits_nothing() {
        let Some(accel) = accel(Mesh::default()) else {
            return;
        };
        let ray = Ray::new(DVec3::ZERO, DVec3::Z);
        assert_eq!(accel.intersect(&ray, f64::INFINITY), None);
    }

    #[test]
    fn bad_indices_are_refused() {
        if std::env::var("BLUTRACE_SKIP_EMBREE").is_ok_and(|v| v == "1") {
            return;
        }
        let mut mesh = unit_triangle();
        mesh.triangles[0][2] = 3;
        let Err(err) = EmbreeAccel::new(Arc::new(mesh)) else {
            panic!("out-of-range indices were accepted");
        };
        assert!(err.to_string().contains("indexes past"), "{err:#}");
    }
}
