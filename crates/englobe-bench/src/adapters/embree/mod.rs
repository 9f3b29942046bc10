//! Intel Embree 3 under test, through englobe's own small FFI ([`ffi`]). One device per thread
//! count, with as many threads as the measurement (`threads=N`), one triangle geometry whose index and
//! vertex buffers Embree allocates (`rtcSetNewGeometryBuffer`, which pads them the way Embree's
//! SIMD loads need) and the harness fills, and the defaults a user gets: build quality medium, no
//! scene flag (`RTC_SCENE_FLAG_ROBUST` only on request). Single rays use `rtcIntersect1` and
//! `rtcOccluded1` with an incoherent context (the default); packets use `rtcIntersect16` and
//! `rtcOccluded16` with a coherent context, as Embree's own tutorials do for camera rays.
//!
//! `ENGLOBE_EMBREE_CONFIG`, if set, is added to the device's configuration string, for Embree's
//! own diagnostics: `verbose=3` prints each build's tree (nodes, leaves, SAH cost), as
//! docs/performance.md quotes it.

pub mod ffi;

use std::ffi::CString;
use std::sync::{Arc, Mutex};

use anyhow::{Context, bail};

use crate::library::{BenchRay, Library, RayResult};
use crate::scene::BenchScene;
use ffi::*;

/// An Embree device: its worker threads and its memory.
pub struct Device(RTCDevice);

// SAFETY: Embree devices may be used from any thread; this one is only released in `drop`.
unsafe impl Send for Device {}
// SAFETY: creating scenes on a device and querying them concurrently is allowed by Embree.
unsafe impl Sync for Device {}

impl Drop for Device {
    fn drop(&mut self) {
        // SAFETY: created by `device`, released once.
        unsafe { rtcReleaseDevice(self.0) }
    }
}

/// The device with `threads` threads, created on first use and kept, so that building a scene does
/// not time the start of Embree's thread pool (an application creates its device once). Only the
/// last one is kept: Embree limits its threads process-wide, and a live one-thread device would
/// hold a two-thread one back.
pub fn device(threads: usize) -> anyhow::Result<Arc<Device>> {
    static CURRENT: Mutex<Option<(usize, Arc<Device>)>> = Mutex::new(None);
    let mut current = CURRENT.lock().unwrap_or_else(|e| e.into_inner());
    if let Some((n, d)) = current.as_ref()
        && *n == threads
    {
        return Ok(d.clone());
    }
    *current = None;
    let extra = std::env::var("ENGLOBE_EMBREE_CONFIG").map(|c| format!(",{c}")).unwrap_or_default();
    let text = format!("threads={threads}{extra}");
    let config = CString::new(text.clone()).context("ENGLOBE_EMBREE_CONFIG holds a NUL byte")?;
    // SAFETY: a valid NUL-terminated configuration string; a null device is checked below.
    let raw = unsafe { rtcNewDevice(config.as_ptr()) };
    if raw.is_null() {
        bail!("Embree refused to create a device with the configuration `{text}` (rtcNewDevice returned null)");
    }
    let d = Arc::new(Device(raw));
    *current = Some((threads, d.clone()));
    Ok(d)
}

/// A committed Embree scene holding the mesh, and its device.
pub struct EmbreeScene {
    scene: RTCScene,
    device: Arc<Device>,
    robust: bool,
}

// SAFETY: Embree documents committed scenes as safe to query from any number of threads at once,
// and the handle is only released in `drop`, which needs exclusive ownership.
unsafe impl Send for EmbreeScene {}
// SAFETY: see above: queries take the scene by shared reference and Embree allows concurrent ones.
unsafe impl Sync for EmbreeScene {}

impl EmbreeScene {
    /// Builds the scene over the mesh on the device with `threads` threads.
    pub fn build(scene: &BenchScene, threads: usize, robust: bool) -> anyhow::Result<Self> {
        let device = self::device(threads)?;
        let raw = device.0;
        // From here on `built` owns the scene and releases it on error.
        let mut built = EmbreeScene { scene: std::ptr::null_mut(), device, robust };
        let mesh = &scene.mesh;
        // SAFETY: the device is valid; every buffer Embree returns is checked for null and written
        // within the item count and stride it was created with; the geometry is released after
        // it is attached (the scene keeps its own reference).
        unsafe {
            built.scene = rtcNewScene(raw);
            if built.scene.is_null() {
                bail!("Embree refused to create a scene");
            }
            rtcSetSceneFlags(built.scene, if robust { RTC_SCENE_FLAG_ROBUST } else { RTC_SCENE_FLAG_NONE });
            rtcSetSceneBuildQuality(built.scene, RTC_BUILD_QUALITY_MEDIUM);
            let geometry = rtcNewGeometry(raw, RTC_GEOMETRY_TYPE_TRIANGLE);
            if geometry.is_null() {
                bail!("Embree refused to create a triangle geometry");
            }
            let vertices = rtcSetNewGeometryBuffer(
                geometry,
                RTC_BUFFER_TYPE_VERTEX,
                0,
                RTC_FORMAT_FLOAT3,
                12,
                mesh.positions().len(),
            ) as *mut [f32; 3];
            let indices = rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 12, mesh.len())
                as *mut [u32; 3];
            if vertices.is_null() || indices.is_null() {
                rtcReleaseGeometry(geometry);
                bail!("Embree could not allocate the mesh's buffers");
            }
            for (i, p) in mesh.positions().iter().enumerate() {
                vertices.add(i).write(p.to_array());
            }
            for (i, t) in mesh.triangles().iter().enumerate() {
                indices.add(i).write(*t);
            }
            rtcSetGeometryBuildQuality(geometry, RTC_BUILD_QUALITY_MEDIUM);
            rtcCommitGeometry(geometry);
            rtcAttachGeometry(built.scene, geometry);
            rtcReleaseGeometry(geometry);
            rtcCommitScene(built.scene);
            let error = rtcGetDeviceError(raw);
            if error != RTC_ERROR_NONE {
                bail!("Embree reported error {error} while building the scene");
            }
        }
        Ok(built)
    }

    /// Embree's version as `MAJOR.MINOR.PATCH`.
    pub fn version(&self) -> String {
        // SAFETY: the device is valid.
        let v = unsafe { rtcGetDeviceProperty(self.device.0, RTC_DEVICE_PROPERTY_VERSION) };
        format!("{}.{}.{}", v / 10000, v / 100 % 100, v % 100)
    }

    fn description(&self, query: &str) -> String {
        let flags = if self.robust { "robust" } else { "none" };
        format!("Embree {}: {query}, build quality medium, scene flags {flags}", self.version())
    }
}

impl Drop for EmbreeScene {
    fn drop(&mut self) {
        if !self.scene.is_null() {
            // SAFETY: created by `build`, released once, before the device it holds.
            unsafe { rtcReleaseScene(self.scene) }
        }
    }
}

/// Embree, one ray at a time.
pub struct EmbreeSingle(EmbreeScene);

impl EmbreeSingle {
    /// Builds the scene on `threads` threads, with `RTC_SCENE_FLAG_ROBUST` if `robust`.
    pub fn build(scene: &BenchScene, threads: usize, robust: bool) -> anyhow::Result<Self> {
        EmbreeScene::build(scene, threads, robust).map(EmbreeSingle).context("Embree")
    }
}

fn rtc_ray(r: &BenchRay) -> RTCRay {
    RTCRay {
        org_x: r.origin.x,
        org_y: r.origin.y,
        org_z: r.origin.z,
        tnear: r.t_min,
        dir_x: r.dir.x,
        dir_y: r.dir.y,
        dir_z: r.dir.z,
        time: 0.0,
        tfar: r.t_max,
        mask: u32::MAX,
        id: 0,
        flags: 0,
    }
}

impl Library for EmbreeSingle {
    fn structure(&self) -> String {
        self.0.description("rtcIntersect1 / rtcOccluded1")
    }

    fn closest_hits(&self, rays: &[BenchRay], out: &mut [RayResult]) {
        let mut context = RTCIntersectContext::new(RTC_INTERSECT_CONTEXT_FLAG_INCOHERENT);
        for (r, out) in rays.iter().zip(out) {
            let mut rh = RTCRayHit {
                ray: rtc_ray(r),
                hit: RTCHit { geomID: RTC_INVALID_GEOMETRY_ID, instID: [RTC_INVALID_GEOMETRY_ID], ..RTCHit::default() },
            };
            // SAFETY: a committed scene, an initialised context and a 16-byte aligned ray/hit.
            unsafe { rtcIntersect1(self.0.scene, &mut context, &mut rh) };
            *out = if rh.hit.geomID == RTC_INVALID_GEOMETRY_ID {
                RayResult::MISS
            } else {
                RayResult::hit(rh.ray.tfar, rh.hit.primID)
            };
        }
    }

    fn any_hits(&self, rays: &[BenchRay], out: &mut [bool]) {
        let mut context = RTCIntersectContext::new(RTC_INTERSECT_CONTEXT_FLAG_INCOHERENT);
        for (r, out) in rays.iter().zip(out) {
            let mut ray = rtc_ray(r);
            // SAFETY: as above; Embree sets tfar to -inf when the ray is occluded.
            unsafe { rtcOccluded1(self.0.scene, &mut context, &mut ray) };
            *out = ray.tfar == f32::NEG_INFINITY;
        }
    }
}

/// Embree, 16-ray packets.
pub struct EmbreePacket16(EmbreeScene);

impl EmbreePacket16 {
    /// Builds the scene on `threads` threads, with `RTC_SCENE_FLAG_ROBUST` if `robust`.
    pub fn build(scene: &BenchScene, threads: usize, robust: bool) -> anyhow::Result<Self> {
        EmbreeScene::build(scene, threads, robust).map(EmbreePacket16).context("Embree")
    }
}

/// Fills a packet with up to 16 rays and returns the mask of the lanes in use.
fn fill_packet(rays: &[BenchRay], p: &mut RTCRay16) -> Valid16 {
    let mut valid = Valid16([0; 16]);
    for (lane, r) in rays.iter().enumerate() {
        valid.0[lane] = -1;
        p.org_x[lane] = r.origin.x;
        p.org_y[lane] = r.origin.y;
        p.org_z[lane] = r.origin.z;
        p.tnear[lane] = r.t_min;
        p.dir_x[lane] = r.dir.x;
        p.dir_y[lane] = r.dir.y;
        p.dir_z[lane] = r.dir.z;
        p.time[lane] = 0.0;
        p.tfar[lane] = r.t_max;
        p.mask[lane] = u32::MAX;
        p.id[lane] = lane as u32;
        p.flags[lane] = 0;
    }
    valid
}

impl Library for EmbreePacket16 {
    fn structure(&self) -> String {
        self.0.description("rtcIntersect16 / rtcOccluded16, 4x4 pixel packets for primary rays")
    }

    fn packet_width(&self) -> usize {
        16
    }

    fn closest_hits(&self, rays: &[BenchRay], out: &mut [RayResult]) {
        let mut context = RTCIntersectContext::new(RTC_INTERSECT_CONTEXT_FLAG_COHERENT);
        let mut packet = RTCRayHit16::default();
        for (rays, out) in rays.chunks(16).zip(out.chunks_mut(16)) {
            let valid = fill_packet(rays, &mut packet.ray);
            packet.hit.geomID = [RTC_INVALID_GEOMETRY_ID; 16];
            packet.hit.instID = [[RTC_INVALID_GEOMETRY_ID; 16]];
            // SAFETY: a committed scene, a 64-byte aligned packet and mask, inactive lanes masked.
            unsafe { rtcIntersect16(valid.0.as_ptr(), self.0.scene, &mut context, &mut packet) };
            for (lane, out) in out.iter_mut().enumerate() {
                *out = if packet.hit.geomID[lane] == RTC_INVALID_GEOMETRY_ID {
                    RayResult::MISS
                } else {
                    RayResult::hit(packet.ray.tfar[lane], packet.hit.primID[lane])
                };
            }
        }
    }

    fn any_hits(&self, rays: &[BenchRay], out: &mut [bool]) {
        let mut context = RTCIntersectContext::new(RTC_INTERSECT_CONTEXT_FLAG_COHERENT);
        let mut packet = RTCRay16::default();
        for (rays, out) in rays.chunks(16).zip(out.chunks_mut(16)) {
            let valid = fill_packet(rays, &mut packet);
            // SAFETY: as above.
            unsafe { rtcOccluded16(valid.0.as_ptr(), self.0.scene, &mut context, &mut packet) };
            for (lane, out) in out.iter_mut().enumerate() {
                *out = packet.tfar[lane] == f32::NEG_INFINITY;
            }
        }
    }
}
