//! The part of Intel Embree 3's C interface the benchmark uses (`embree3/rtcore*.h`, version
//! 3.13), declared by hand. Layouts follow the headers as Debian's `libembree-dev` ships them:
//! `RTC_MAX_INSTANCE_LEVEL_COUNT` 1 and `RTC_MIN_WIDTH` 0, so the intersect context is flags,
//! filter pointer and one instance id (24 bytes); `RTCRayHit` is 80 bytes aligned to 16 and
//! `RTCRayHit16` 1280 bytes aligned to 64. The tests check every size and alignment.

#![allow(non_camel_case_types, non_snake_case, missing_docs)]

use std::ffi::{c_char, c_int, c_uint, c_void};

pub type RTCDevice = *mut c_void;
pub type RTCScene = *mut c_void;
pub type RTCGeometry = *mut c_void;

pub const RTC_GEOMETRY_TYPE_TRIANGLE: c_int = 0;
pub const RTC_BUFFER_TYPE_INDEX: c_int = 0;
pub const RTC_BUFFER_TYPE_VERTEX: c_int = 1;
pub const RTC_FORMAT_UINT3: c_int = 0x5003;
pub const RTC_FORMAT_FLOAT3: c_int = 0x9003;
pub const RTC_BUILD_QUALITY_MEDIUM: c_int = 1;
pub const RTC_SCENE_FLAG_NONE: c_int = 0;
pub const RTC_SCENE_FLAG_ROBUST: c_int = 1 << 2;
pub const RTC_INTERSECT_CONTEXT_FLAG_INCOHERENT: c_int = 0;
pub const RTC_INTERSECT_CONTEXT_FLAG_COHERENT: c_int = 1;
pub const RTC_INVALID_GEOMETRY_ID: c_uint = c_uint::MAX;
pub const RTC_ERROR_NONE: c_int = 0;
pub const RTC_DEVICE_PROPERTY_VERSION: c_int = 0;
pub const RTC_DEVICE_PROPERTY_NATIVE_RAY16_SUPPORTED: c_int = 34;

/// `struct RTCIntersectContext` with one instance level and no minimum width.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct RTCIntersectContext {
    pub flags: c_int,
    pub filter: Option<unsafe extern "C" fn(*const c_void)>,
    pub instID: [c_uint; 1],
}

impl RTCIntersectContext {
    /// What the header's inline `rtcInitIntersectContext` sets, with the given flags.
    pub fn new(flags: c_int) -> Self {
        RTCIntersectContext { flags, filter: None, instID: [RTC_INVALID_GEOMETRY_ID] }
    }
}

#[repr(C, align(16))]
#[derive(Clone, Copy, Debug, Default)]
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

#[repr(C, align(16))]
#[derive(Clone, Copy, Debug, Default)]
pub struct RTCHit {
    pub Ng_x: f32,
    pub Ng_y: f32,
    pub Ng_z: f32,
    pub u: f32,
    pub v: f32,
    pub primID: c_uint,
    pub geomID: c_uint,
    pub instID: [c_uint; 1],
}

#[repr(C)]
#[derive(Clone, Copy, Debug, Default)]
pub struct RTCRayHit {
    pub ray: RTCRay,
    pub hit: RTCHit,
}

#[repr(C, align(64))]
#[derive(Clone, Copy, Debug, Default)]
pub struct RTCRay16 {
    pub org_x: [f32; 16],
    pub org_y: [f32; 16],
    pub org_z: [f32; 16],
    pub tnear: [f32; 16],
    pub dir_x: [f32; 16],
    pub dir_y: [f32; 16],
    pub dir_z: [f32; 16],
    pub time: [f32; 16],
    pub tfar: [f32; 16],
    pub mask: [c_uint; 16],
    pub id: [c_uint; 16],
    pub flags: [c_uint; 16],
}

#[repr(C, align(64))]
#[derive(Clone, Copy, Debug, Default)]
pub struct RTCHit16 {
    pub Ng_x: [f32; 16],
    pub Ng_y: [f32; 16],
    pub Ng_z: [f32; 16],
    pub u: [f32; 16],
    pub v: [f32; 16],
    pub primID: [c_uint; 16],
    pub geomID: [c_uint; 16],
    pub instID: [[c_uint; 16]; 1],
}

#[repr(C)]
#[derive(Clone, Copy, Debug, Default)]
pub struct RTCRayHit16 {
    pub ray: RTCRay16,
    pub hit: RTCHit16,
}

/// The `valid` mask of a 16-wide query: -1 for an active lane, 0 for an inactive one, aligned like
/// the packet.
#[repr(C, align(64))]
#[derive(Clone, Copy, Debug)]
pub struct Valid16(pub [c_int; 16]);

unsafe extern "C" {
    pub fn rtcNewDevice(config: *const c_char) -> RTCDevice;
    pub fn rtcReleaseDevice(device: RTCDevice);
    pub fn rtcGetDeviceError(device: RTCDevice) -> c_int;
    pub fn rtcGetDeviceProperty(device: RTCDevice, prop: c_int) -> isize;

    pub fn rtcNewScene(device: RTCDevice) -> RTCScene;
    pub fn rtcReleaseScene(scene: RTCScene);
    pub fn rtcSetSceneFlags(scene: RTCScene, flags: c_int);
    pub fn rtcSetSceneBuildQuality(scene: RTCScene, quality: c_int);
    pub fn rtcAttachGeometry(scene: RTCScene, geometry: RTCGeometry) -> c_uint;
    pub fn rtcCommitScene(scene: RTCScene);

    pub fn rtcNewGeometry(device: RTCDevice, kind: c_int) -> RTCGeometry;
    pub fn rtcReleaseGeometry(geometry: RTCGeometry);
    pub fn rtcSetGeometryBuildQuality(geometry: RTCGeometry, quality: c_int);
    pub fn rtcSetNewGeometryBuffer(
        geometry: RTCGeometry,
        kind: c_int,
        slot: c_uint,
        format: c_int,
        byte_stride: usize,
        item_count: usize,
    ) -> *mut c_void;
    pub fn rtcCommitGeometry(geometry: RTCGeometry);

    pub fn rtcIntersect1(scene: RTCScene, context: *mut RTCIntersectContext, rayhit: *mut RTCRayHit);
    pub fn rtcOccluded1(scene: RTCScene, context: *mut RTCIntersectContext, ray: *mut RTCRay);
    pub fn rtcIntersect16(
        valid: *const c_int,
        scene: RTCScene,
        context: *mut RTCIntersectContext,
        rayhit: *mut RTCRayHit16,
    );
    pub fn rtcOccluded16(valid: *const c_int, scene: RTCScene, context: *mut RTCIntersectContext, ray: *mut RTCRay16);
}

#[cfg(test)]
mod tests {
    use std::mem::{align_of, offset_of, size_of};

    use super::*;

    #[test]
    fn layouts_match_the_headers() {
        assert_eq!((size_of::<RTCRay>(), align_of::<RTCRay>()), (48, 16));
        assert_eq!((size_of::<RTCHit>(), align_of::<RTCHit>()), (32, 16));
        assert_eq!((size_of::<RTCRayHit>(), align_of::<RTCRayHit>()), (80, 16));
        assert_eq!((size_of::<RTCRay16>(), align_of::<RTCRay16>()), (768, 64));
        assert_eq!((size_of::<RTCRayHit16>(), align_of::<RTCRayHit16>()), (1280, 64));
        assert_eq!(offset_of!(RTCRayHit16, hit), 768);
        assert_eq!((size_of::<RTCIntersectContext>(), align_of::<RTCIntersectContext>()), (24, 8));
        assert_eq!(offset_of!(RTCIntersectContext, filter), 8);
        assert_eq!(offset_of!(RTCIntersectContext, instID), 16);
        assert_eq!(align_of::<Valid16>(), 64);
    }
}
