//! Embree 3 through a minimal hand-written FFI (Debian `libembree-dev` 3.13.5): the
//! reference a user would pick, measured on the same triangles and rays as the k-d tree.
//!
//! Only what the benchmark needs is declared: a device, one scene holding one triangle
//! geometry (vertices unshared, three per triangle, so Embree's `primID` is the soup's
//! triangle index), the single-ray queries `rtcIntersect1` / `rtcOccluded1` and the packet
//! queries `rtcIntersectN` / `rtcOccludedN` for N = 4, 8, 16.
//! The struct layouts mirror `/usr/include/embree3/rtcore_ray.h` and `rtcore_common.h`
//! for this build (`RTC_MAX_INSTANCE_LEVEL_COUNT 1`, `RTC_MIN_WIDTH 0`); the compile-time
//! asserts below pin their sizes and alignments.

use glam::Vec3;
use kdtree::Ray;
use std::ffi::{c_char, c_uint, c_void, CString};
use std::sync::atomic::{AtomicIsize, Ordering};
use std::sync::Arc;

/// Runs `queries` with subnormals flushed to zero (MXCSR's FTZ and DAZ bits), as Embree's
/// documentation asks of the threads that call it for full speed, and puts the thread's
/// mode back afterwards. Without them, rays that start at `f32::MIN_POSITIVE` (the
/// renderer's spawned rays) cost Embree microcode assists on Intel cores: its soft-shadow
/// rays ran at about three quarters of the speed. The benchmark sets the mode once per
/// chunk of rays; around each call it cost Embree's cheapest rays 4–5 %.
///
/// The Rust code between the calls only moves rays and answers, so the flush changes
/// nothing there.
pub(crate) fn flushing_subnormals<R>(queries: impl FnOnce() -> R) -> R {
    #[cfg(target_arch = "x86_64")]
    {
        use std::arch::asm;
        const FTZ_DAZ: u32 = 0x8040;
        let mut mode = 0u32;
        // SAFETY: `stmxcsr` stores the 4-byte control word into `mode`; `ldmxcsr` loads
        // one from a valid u32. Only the flush bits change, until `queries` returns.
        unsafe { asm!("stmxcsr [{}]", in(reg) &mut mode, options(nostack, preserves_flags)) };
        let flushing = mode | FTZ_DAZ;
        unsafe { asm!("ldmxcsr [{}]", in(reg) &flushing, options(nostack, preserves_flags)) };
        let answer = queries();
        unsafe { asm!("ldmxcsr [{}]", in(reg) &mode, options(nostack, preserves_flags)) };
        answer
    }
    #[cfg(not(target_arch = "x86_64"))]
    queries()
}

type RtcDevice = *mut c_void;
type RtcScene = *mut c_void;
type RtcGeometry = *mut c_void;

const RTC_INVALID_GEOMETRY_ID: u32 = u32::MAX;
const RTC_GEOMETRY_TYPE_TRIANGLE: u32 = 0;
const RTC_BUFFER_TYPE_INDEX: u32 = 0;
const RTC_BUFFER_TYPE_VERTEX: u32 = 1;
const RTC_FORMAT_UINT3: u32 = 0x5003;
const RTC_FORMAT_FLOAT3: u32 = 0x9003;
const RTC_INTERSECT_CONTEXT_FLAG_COHERENT: u32 = 1;
const RTC_INTERSECT_CONTEXT_FLAG_INCOHERENT: u32 = 0;
const RTC_DEVICE_PROPERTY_VERSION: u32 = 0;

/// `RTCSceneFlags`.
pub const SCENE_FLAG_NONE: u32 = 0;
pub const SCENE_FLAG_COMPACT: u32 = 1 << 1;
pub const SCENE_FLAG_ROBUST: u32 = 1 << 2;

/// `RTCBuildQuality`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Quality {
    Low = 0,
    Medium = 1,
    High = 2,
}

impl Quality {
    pub fn name(self) -> &'static str {
        match self {
            Quality::Low => "low",
            Quality::Medium => "medium",
            Quality::High => "high",
        }
    }
}

/// `struct RTCIntersectContext`: flags, filter pointer, instID[1] (24 bytes with padding).
#[repr(C)]
struct RtcIntersectContext {
    flags: u32,
    filter: Option<unsafe extern "C" fn(*const c_void)>,
    inst_id: [u32; 1],
}

/// `struct RTC_ALIGN(16) RTCRay` (48 bytes).
#[repr(C, align(16))]
#[derive(Clone, Copy)]
struct RtcRay {
    org: [f32; 3],
    tnear: f32,
    dir: [f32; 3],
    time: f32,
    tfar: f32,
    mask: u32,
    id: u32,
    flags: u32,
}

/// `struct RTC_ALIGN(16) RTCHit` (32 bytes).
#[repr(C, align(16))]
#[derive(Clone, Copy)]
struct RtcHit {
    ng: [f32; 3],
    u: f32,
    v: f32,
    prim_id: u32,
    geom_id: u32,
    inst_id: [u32; 1],
}

/// `struct RTCRayHit` (80 bytes, 16-byte aligned through its members).
#[repr(C)]
#[derive(Clone, Copy)]
struct RtcRayHit {
    ray: RtcRay,
    hit: RtcHit,
}

/// `struct RTCRayN` for N = 4, 8, 16: lane-major arrays, 48·N bytes, no padding.
#[repr(C)]
#[derive(Clone, Copy)]
struct RtcRayN<const N: usize> {
    org: [[f32; N]; 3],
    tnear: [f32; N],
    dir: [[f32; N]; 3],
    time: [f32; N],
    tfar: [f32; N],
    mask: [u32; N],
    id: [u32; N],
    flags: [u32; N],
}

/// `struct RTCRayHitN`: `RTCRayN` then `RTCHitN`, lane-major arrays (80·N bytes; one
/// instance level).
#[repr(C)]
struct RtcRayHitN<const N: usize> {
    ray: RtcRayN<N>,
    ng: [[f32; N]; 3],
    u: [f32; N],
    v: [f32; N],
    prim_id: [u32; N],
    geom_id: [u32; N],
    inst_id: [u32; N],
}

/// A packet's structs and its `valid` mask start at 16, 32 or 64 bytes for N = 4, 8, 16;
/// 64 serves all three. The structs inside hold only 4-byte fields, so the wrapper adds no
/// padding between them.
#[repr(C, align(64))]
struct Aligned<T>(T);

const _: () = {
    assert!(std::mem::size_of::<RtcRayHitN<4>>() == 320);
    assert!(std::mem::size_of::<RtcRayN<4>>() == 192);
    assert!(std::mem::size_of::<RtcRayHitN<16>>() == 1280);
    assert!(std::mem::size_of::<RtcRayN<16>>() == 768);
    assert!(std::mem::size_of::<RtcIntersectContext>() == 24);
    assert!(std::mem::size_of::<RtcRay>() == 48);
    assert!(std::mem::align_of::<RtcRay>() == 16);
    assert!(std::mem::size_of::<RtcHit>() == 32);
    assert!(std::mem::size_of::<RtcRayHit>() == 80);
    assert!(std::mem::align_of::<RtcRayHit>() == 16);
};

/// `rtcIntersectN` / `rtcOccludedN`: valid mask, scene, context, the N-lane packet.
type PacketFn = unsafe extern "C" fn(*const i32, RtcScene, *mut RtcIntersectContext, *mut c_void);

type MemoryMonitor = unsafe extern "C" fn(ptr: *mut c_void, bytes: isize, post: bool) -> bool;

#[link(name = "embree3")]
extern "C" {
    fn rtcNewDevice(config: *const c_char) -> RtcDevice;
    fn rtcReleaseDevice(device: RtcDevice);
    fn rtcGetDeviceError(device: RtcDevice) -> u32;
    fn rtcGetDeviceProperty(device: RtcDevice, prop: u32) -> isize;
    fn rtcSetDeviceMemoryMonitorFunction(
        device: RtcDevice,
        monitor: Option<MemoryMonitor>,
        user: *mut c_void,
    );
    fn rtcNewScene(device: RtcDevice) -> RtcScene;
    fn rtcReleaseScene(scene: RtcScene);
    fn rtcSetSceneBuildQuality(scene: RtcScene, quality: u32);
    fn rtcSetSceneFlags(scene: RtcScene, flags: u32);
    fn rtcNewGeometry(device: RtcDevice, kind: u32) -> RtcGeometry;
    fn rtcSetNewGeometryBuffer(
        geometry: RtcGeometry,
        kind: u32,
        slot: c_uint,
        format: u32,
        byte_stride: usize,
        item_count: usize,
    ) -> *mut c_void;
    fn rtcCommitGeometry(geometry: RtcGeometry);
    fn rtcAttachGeometry(scene: RtcScene, geometry: RtcGeometry) -> c_uint;
    fn rtcReleaseGeometry(geometry: RtcGeometry);
    fn rtcCommitScene(scene: RtcScene);
    fn rtcIntersect1(scene: RtcScene, context: *mut RtcIntersectContext, rayhit: *mut RtcRayHit);
    fn rtcOccluded1(scene: RtcScene, context: *mut RtcIntersectContext, ray: *mut RtcRay);
    fn rtcIntersect4(
        valid: *const i32,
        scene: RtcScene,
        context: *mut RtcIntersectContext,
        rayhit: *mut c_void,
    );
    fn rtcIntersect8(
        valid: *const i32,
        scene: RtcScene,
        context: *mut RtcIntersectContext,
        rayhit: *mut c_void,
    );
    fn rtcIntersect16(
        valid: *const i32,
        scene: RtcScene,
        context: *mut RtcIntersectContext,
        rayhit: *mut c_void,
    );
    fn rtcOccluded4(
        valid: *const i32,
        scene: RtcScene,
        context: *mut RtcIntersectContext,
        ray: *mut c_void,
    );
    fn rtcOccluded8(
        valid: *const i32,
        scene: RtcScene,
        context: *mut RtcIntersectContext,
        ray: *mut c_void,
    );
    fn rtcOccluded16(
        valid: *const i32,
        scene: RtcScene,
        context: *mut RtcIntersectContext,
        ray: *mut c_void,
    );
}

/// The header's inline `rtcInitIntersectContext`, for this build's configuration.
fn init_context() -> RtcIntersectContext {
    RtcIntersectContext {
        flags: RTC_INTERSECT_CONTEXT_FLAG_INCOHERENT,
        filter: None,
        inst_id: [RTC_INVALID_GEOMETRY_ID],
    }
}

#[derive(Debug, thiserror::Error)]
pub enum EmbreeError {
    #[error("Embree could not create a device with config {config:?} (error code {code})")]
    Device { config: String, code: u32 },
    #[error("Embree failed to {what} (error code {code})")]
    Call { what: &'static str, code: u32 },
    #[error("{count} triangles is more than one Embree geometry holds")]
    TooMany { count: usize },
}

/// Live bytes Embree reports through its memory monitor (buffers, BVH, scratch).
unsafe extern "C" fn monitor(ptr: *mut c_void, bytes: isize, _post: bool) -> bool {
    // SAFETY: `ptr` is the AtomicIsize owned by the Device, which outlives the callback.
    let counter = unsafe { &*(ptr as *const AtomicIsize) };
    counter.fetch_add(bytes, Ordering::Relaxed);
    true
}

/// An Embree device (its own thread pool for builds).
pub struct Device {
    raw: RtcDevice,
    // Boxed so its address stays fixed for the memory-monitor callback.
    memory: Box<AtomicIsize>,
}

// SAFETY: Embree devices are thread-safe handles (the API is documented as such).
unsafe impl Send for Device {}
unsafe impl Sync for Device {}

impl Device {
    /// A device whose builds use `threads` threads (0: all hardware threads).
    pub fn new(threads: usize) -> Result<Arc<Device>, EmbreeError> {
        let config = format!("threads={threads},verbose=0");
        let c = CString::new(config.clone()).expect("no NUL in a formatted config");
        // SAFETY: a valid NUL-terminated config string; a null return is checked.
        let raw = unsafe { rtcNewDevice(c.as_ptr()) };
        if raw.is_null() {
            // SAFETY: rtcGetDeviceError(NULL) returns the thread-local creation error.
            let code = unsafe { rtcGetDeviceError(std::ptr::null_mut()) };
            return Err(EmbreeError::Device { config, code });
        }
        let memory = Box::new(AtomicIsize::new(0));
        // SAFETY: the counter lives in a Box owned by the Device, released after the
        // device itself (Drop releases the device first).
        unsafe {
            rtcSetDeviceMemoryMonitorFunction(
                raw,
                Some(monitor),
                &*memory as *const AtomicIsize as *mut c_void,
            )
        };
        Ok(Arc::new(Device { raw, memory }))
    }

    /// Embree's version as `major.minor.patch`.
    pub fn version(&self) -> String {
        // SAFETY: valid device handle.
        let v = unsafe { rtcGetDeviceProperty(self.raw, RTC_DEVICE_PROPERTY_VERSION) };
        format!("{}.{}.{}", v / 10000, (v / 100) % 100, v % 100)
    }

    /// Bytes currently allocated by this device, as its memory monitor reports them.
    pub fn memory_bytes(&self) -> isize {
        self.memory.load(Ordering::Relaxed)
    }

    fn check(&self, what: &'static str) -> Result<(), EmbreeError> {
        // SAFETY: valid device handle.
        match unsafe { rtcGetDeviceError(self.raw) } {
            0 => Ok(()),
            code => Err(EmbreeError::Call { what, code }),
        }
    }
}

impl Drop for Device {
    fn drop(&mut self) {
        // SAFETY: every scene holds an Arc of its device, so none is alive here.
        unsafe { rtcReleaseDevice(self.raw) };
    }
}

/// A committed Embree scene over a triangle list, answering single-ray queries.
pub struct EmbreeScene {
    device: Arc<Device>,
    scene: RtcScene,
    /// Device memory attributed to this scene (monitor delta over its construction).
    bytes: isize,
}

// SAFETY: a committed scene may be queried from any number of threads at once
// (rtcIntersect1/rtcOccluded1 are thread-safe); it is never modified after commit.
unsafe impl Send for EmbreeScene {}
unsafe impl Sync for EmbreeScene {}

impl EmbreeScene {
    /// High-quality build on a device using all hardware threads.
    pub fn new(triangles: &[[Vec3; 3]]) -> Result<EmbreeScene, EmbreeError> {
        Self::build(&Device::new(0)?, triangles, Quality::High, SCENE_FLAG_NONE)
    }

    /// Build on `device` with the given build quality and `RTCSceneFlags`.
    pub fn build(
        device: &Arc<Device>,
        triangles: &[[Vec3; 3]],
        quality: Quality,
        flags: u32,
    ) -> Result<EmbreeScene, EmbreeError> {
        let n = triangles.len();
        if n.checked_mul(3).is_none_or(|v| v > u32::MAX as usize) {
            return Err(EmbreeError::TooMany { count: n });
        }
        let before = device.memory_bytes();
        // SAFETY: valid device; every handle is checked before use and released on all
        // paths; the buffers Embree returns hold exactly the item counts written.
        unsafe {
            let scene = rtcNewScene(device.raw);
            if scene.is_null() {
                device.check("create a scene")?;
                return Err(EmbreeError::Call {
                    what: "create a scene",
                    code: 1,
                });
            }
            let mut out = EmbreeScene {
                device: device.clone(),
                scene,
                bytes: 0,
            };
            rtcSetSceneBuildQuality(scene, quality as u32);
            rtcSetSceneFlags(scene, flags);
            let geom = rtcNewGeometry(device.raw, RTC_GEOMETRY_TYPE_TRIANGLE);
            if geom.is_null() {
                device.check("create a triangle geometry")?;
                return Err(EmbreeError::Call {
                    what: "create a triangle geometry",
                    code: 1,
                });
            }
            let verts = rtcSetNewGeometryBuffer(
                geom,
                RTC_BUFFER_TYPE_VERTEX,
                0,
                RTC_FORMAT_FLOAT3,
                12,
                3 * n,
            ) as *mut [f32; 3];
            let index =
                rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 12, n)
                    as *mut [u32; 3];
            if verts.is_null() || index.is_null() {
                rtcReleaseGeometry(geom);
                device.check("allocate geometry buffers")?;
                return Err(EmbreeError::Call {
                    what: "allocate geometry buffers",
                    code: 4,
                });
            }
            if n > 0 {
                let verts = std::slice::from_raw_parts_mut(verts, 3 * n);
                let index = std::slice::from_raw_parts_mut(index, n);
                for (i, t) in triangles.iter().enumerate() {
                    verts[3 * i] = t[0].to_array();
                    verts[3 * i + 1] = t[1].to_array();
                    verts[3 * i + 2] = t[2].to_array();
                    let b = 3 * i as u32;
                    index[i] = [b, b + 1, b + 2];
                }
            }
            rtcCommitGeometry(geom);
            rtcAttachGeometry(scene, geom);
            rtcReleaseGeometry(geom);
            rtcCommitScene(scene);
            device.check("build the scene")?;
            out.bytes = device.memory_bytes() - before;
            Ok(out)
        }
    }

    /// Bytes Embree allocated for this scene (vertex and index buffers plus the BVH).
    pub fn memory_bytes(&self) -> isize {
        self.bytes
    }

    fn rtc_ray(ray: &Ray) -> RtcRay {
        RtcRay {
            org: ray.origin.to_array(),
            tnear: ray.tmin,
            dir: ray.dir.to_array(),
            time: 0.0,
            tfar: ray.tmax,
            mask: u32::MAX,
            id: 0,
            flags: 0,
        }
    }

    /// Closest hit in [tmin, tmax]: (t, triangle index, u, v) with
    /// p = (1−u−v)·v0 + u·v1 + v·v2.
    #[inline]
    pub fn intersect(&self, ray: &Ray) -> Option<(f32, u32, f32, f32)> {
        let mut rh = RtcRayHit {
            ray: Self::rtc_ray(ray),
            hit: RtcHit {
                ng: [0.0; 3],
                u: 0.0,
                v: 0.0,
                prim_id: RTC_INVALID_GEOMETRY_ID,
                geom_id: RTC_INVALID_GEOMETRY_ID,
                inst_id: [RTC_INVALID_GEOMETRY_ID],
            },
        };
        let mut ctx = init_context();
        // SAFETY: committed scene; ctx and rh are valid, rh is 16-byte aligned.
        unsafe { rtcIntersect1(self.scene, &mut ctx, &mut rh) };
        (rh.hit.geom_id != RTC_INVALID_GEOMETRY_ID).then_some((
            rh.ray.tfar,
            rh.hit.prim_id,
            rh.hit.u,
            rh.hit.v,
        ))
    }

    /// N rays lane by lane, as the packet calls take them.
    fn rtc_ray_n<const N: usize>(rays: &[Ray; N]) -> RtcRayN<N> {
        let lane = |f: &dyn Fn(&Ray) -> f32| rays.each_ref().map(f);
        RtcRayN {
            org: [
                lane(&|r| r.origin.x),
                lane(&|r| r.origin.y),
                lane(&|r| r.origin.z),
            ],
            tnear: lane(&|r| r.tmin),
            dir: [lane(&|r| r.dir.x), lane(&|r| r.dir.y), lane(&|r| r.dir.z)],
            time: [0.0; N],
            tfar: lane(&|r| r.tmax),
            mask: [u32::MAX; N],
            id: [0; N],
            flags: [0; N],
        }
    }

    /// Neighbouring pixels' rays: Embree's hint for rays that travel together.
    fn coherent_context() -> RtcIntersectContext {
        RtcIntersectContext {
            flags: RTC_INTERSECT_CONTEXT_FLAG_COHERENT,
            ..init_context()
        }
    }

    /// Calls the N-lane one of `calls` (the 4-, 8- and 16-lane functions) on `packet`,
    /// all lanes valid, with the coherent context.
    ///
    /// # Safety
    /// `packet` points to the N-lane struct the call takes, aligned to 64 bytes.
    ///
    /// # Panics
    /// For N other than 4, 8 or 16.
    unsafe fn packet_call<const N: usize>(&self, calls: [PacketFn; 3], packet: *mut c_void) {
        let call = match N {
            4 => calls[0],
            8 => calls[1],
            16 => calls[2],
            _ => panic!("Embree has no packets of {N} rays"),
        };
        let valid = Aligned([-1i32; N]);
        let mut ctx = Self::coherent_context();
        // SAFETY: committed scene; `valid` holds N lanes aligned to 64 bytes, `ctx` is
        // initialised, `packet` is the caller's N-lane struct and `call` takes N lanes.
        unsafe { call(valid.0.as_ptr(), self.scene, &mut ctx, packet) }
    }

    /// [`EmbreeScene::intersect`] on N = 4, 8 or 16 rays with one `rtcIntersectN` call.
    ///
    /// # Panics
    /// For any other N.
    #[inline]
    pub fn intersect_n<const N: usize>(
        &self,
        rays: &[Ray; N],
    ) -> [Option<(f32, u32, f32, f32)>; N] {
        let mut rh = Aligned(RtcRayHitN {
            ray: Self::rtc_ray_n(rays),
            ng: [[0.0; N]; 3],
            u: [0.0; N],
            v: [0.0; N],
            prim_id: [RTC_INVALID_GEOMETRY_ID; N],
            geom_id: [RTC_INVALID_GEOMETRY_ID; N],
            inst_id: [RTC_INVALID_GEOMETRY_ID; N],
        });
        // SAFETY: `rh` is an `RTCRayHitN` of N lanes (size pinned above), 64-byte aligned.
        unsafe {
            self.packet_call::<N>(
                [rtcIntersect4, rtcIntersect8, rtcIntersect16],
                (&mut rh.0 as *mut RtcRayHitN<N>).cast(),
            )
        };
        let rh = rh.0;
        std::array::from_fn(|l| {
            (rh.geom_id[l] != RTC_INVALID_GEOMETRY_ID).then_some((
                rh.ray.tfar[l],
                rh.prim_id[l],
                rh.u[l],
                rh.v[l],
            ))
        })
    }

    /// [`EmbreeScene::occluded`] on N = 4, 8 or 16 rays with one `rtcOccludedN` call.
    ///
    /// # Panics
    /// For any other N.
    #[inline]
    pub fn occluded_n<const N: usize>(&self, rays: &[Ray; N]) -> [bool; N] {
        let mut r = Aligned(Self::rtc_ray_n(rays));
        // SAFETY: `r` is an `RTCRayN` of N lanes (size pinned above), 64-byte aligned.
        unsafe {
            self.packet_call::<N>(
                [rtcOccluded4, rtcOccluded8, rtcOccluded16],
                (&mut r.0 as *mut RtcRayN<N>).cast(),
            )
        };
        r.0.tfar.map(|t| t == f32::NEG_INFINITY)
    }

    /// Whether anything blocks the ray in [tmin, tmax] (Embree sets tfar to −inf).
    #[inline]
    pub fn occluded(&self, ray: &Ray) -> bool {
        let mut r = Self::rtc_ray(ray);
        let mut ctx = init_context();
        // SAFETY: committed scene; ctx and r are valid, r is 16-byte aligned.
        unsafe { rtcOccluded1(self.scene, &mut ctx, &mut r) };
        r.tfar == f32::NEG_INFINITY
    }

    pub fn device(&self) -> &Arc<Device> {
        &self.device
    }
}

impl Drop for EmbreeScene {
    fn drop(&mut self) {
        // SAFETY: the scene handle is valid and released once; the device outlives it.
        unsafe { rtcReleaseScene(self.scene) };
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn quad() -> Vec<[Vec3; 3]> {
        // Unit square at z = 2 split into two triangles, plus a small triangle behind it.
        vec![
            [
                Vec3::new(0.0, 0.0, 2.0),
                Vec3::new(1.0, 0.0, 2.0),
                Vec3::new(1.0, 1.0, 2.0),
            ],
            [
                Vec3::new(0.0, 0.0, 2.0),
                Vec3::new(1.0, 1.0, 2.0),
                Vec3::new(0.0, 1.0, 2.0),
            ],
            [
                Vec3::new(0.0, 0.0, 5.0),
                Vec3::new(1.0, 0.0, 5.0),
                Vec3::new(0.0, 1.0, 5.0),
            ],
        ]
    }

    #[test]
    fn hits_the_front_triangle_with_its_barycentrics() {
        let s = EmbreeScene::new(&quad()).unwrap();
        let r = Ray::new(Vec3::new(0.75, 0.25, 0.0), Vec3::Z, 0.0, f32::INFINITY);
        let (t, prim, u, v) = s.intersect(&r).unwrap();
        assert!((t - 2.0).abs() < 1e-6, "t = {t}");
        assert_eq!(prim, 0);
        // p = (1−u−v)·(0,0) + u·(1,0) + v·(1,1) = (0.75, 0.25) → u = 0.5, v = 0.25.
        assert!(
            (u - 0.5).abs() < 1e-6 && (v - 0.25).abs() < 1e-6,
            "u {u} v {v}"
        );
        assert!(s.occluded(&r));
        // The interval excludes the front quad: the back triangle at t = 5 is found.
        let r2 = Ray::new(Vec3::new(0.1, 0.1, 0.0), Vec3::Z, 3.0, 10.0);
        assert_eq!(s.intersect(&r2).map(|h| h.1), Some(2));
        // Too short to reach anything.
        let r3 = Ray::new(Vec3::new(0.1, 0.1, 0.0), Vec3::Z, 0.0, 1.5);
        assert!(s.intersect(&r3).is_none());
        assert!(!s.occluded(&r3));
        assert!(s.memory_bytes() > 0);
    }

    #[test]
    fn packets_of_four_eight_and_sixteen_get_the_single_answers_lane_by_lane() {
        let s = EmbreeScene::new(&quad()).unwrap();
        let four = [
            Ray::new(Vec3::new(0.75, 0.25, 0.0), Vec3::Z, 0.0, f32::INFINITY),
            Ray::new(Vec3::new(0.1, 0.1, 0.0), Vec3::Z, 3.0, 10.0),
            Ray::new(Vec3::new(0.1, 0.1, 0.0), Vec3::Z, 0.0, 1.5),
            Ray::new(Vec3::new(0.25, 0.75, 0.0), Vec3::Z, 0.0, f32::INFINITY),
        ];
        let got = s.intersect_n(&four);
        assert_eq!(
            got.map(|h| h.map(|h| h.1)),
            [Some(0), Some(2), None, Some(1)]
        );
        assert_eq!(s.occluded_n(&four), [true, true, false, true]);
        // Wider packets: the same four rays in a different order per group of four.
        let eight: [Ray; 8] = std::array::from_fn(|l| four[(l + l / 4) % 4]);
        let sixteen: [Ray; 16] = std::array::from_fn(|l| four[(l + l / 4) % 4]);
        for (r, g) in eight.iter().zip(s.intersect_n(&eight)) {
            assert_eq!(g, s.intersect(r));
        }
        for (r, g) in sixteen.iter().zip(s.intersect_n(&sixteen)) {
            assert_eq!(g, s.intersect(r));
        }
        for (r, o) in sixteen.iter().zip(s.occluded_n(&sixteen)) {
            assert_eq!(o, s.occluded(r));
        }
        assert_eq!(s.occluded_n(&eight).iter().filter(|&&o| o).count(), 6);
    }
}
