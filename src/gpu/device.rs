//! Platform and device discovery and the `--device` selection rule.

use crate::error::{Error, Result};
use opencl3::device::{CL_DEVICE_TYPE_ALL, CL_DEVICE_TYPE_CPU, CL_DEVICE_TYPE_GPU, Device};
use opencl3::platform::get_platforms;
use opencl3::types::cl_device_id;
use serde::Serialize;

/// What `shapecue devices` prints about one device.
#[derive(Clone, Debug, Serialize)]
pub struct DeviceInfo {
    /// Index in the flat list over all platforms (what `--device N` takes).
    pub index: usize,
    /// Platform name.
    pub platform: String,
    /// Device name.
    pub name: String,
    /// "GPU", "CPU", "ACCELERATOR" or "OTHER".
    pub kind: String,
    /// OpenCL version string of the device.
    pub version: String,
    /// Compute units.
    pub compute_units: u32,
    /// Global memory in bytes.
    pub global_mem: u64,
    /// Largest single allocation in bytes.
    pub max_alloc: u64,
    /// cl_khr_fp64 (double precision).
    pub fp64: bool,
    /// cl_khr_gl_sharing (GL interop).
    pub gl_sharing: bool,
    /// cl_khr_int64_base_atomics (needed by f64 atomic accumulation).
    pub int64_atomics: bool,
    /// cl_ext_float_atomics with a global atomic add for f32
    /// (`CL_DEVICE_SINGLE_FP_ATOMIC_CAPABILITIES_EXT`), for `--accumulate atomic-native`.
    pub float_atomics: bool,
    /// The same for f64 (`CL_DEVICE_DOUBLE_FP_ATOMIC_CAPABILITIES_EXT`).
    pub double_atomics: bool,
    /// `CL_FP_CORRECTLY_ROUNDED_DIVIDE_SQRT` in `CL_DEVICE_SINGLE_FP_CONFIG`:
    /// f32 divide and square root can be built correctly rounded
    /// (`-cl-fp32-correctly-rounded-divide-sqrt`), as the CPU twins compute
    /// them. Without it, the promises of bits hold only within a tolerance.
    pub correctly_rounded_div_sqrt: bool,
    /// NVIDIA's CUDA platform, whose OpenCL C compiler takes inline PTX:
    /// float atomic adds through `red.global.add` where `cl_ext_float_atomics`
    /// is missing (`--accumulate atomic-native`).
    pub ptx: bool,
    /// `CL_DEVICE_NATIVE_VECTOR_WIDTH_FLOAT`: floats per SIMD register.
    pub native_float_width: u32,
    /// `CL_DEVICE_NATIVE_VECTOR_WIDTH_DOUBLE` (0 without double precision).
    pub native_double_width: u32,
    #[serde(skip)]
    pub(crate) id: cl_device_id,
}

// SAFETY: cl_device_id is an opaque handle that OpenCL allows to be used from any thread.
unsafe impl Send for DeviceInfo {}
unsafe impl Sync for DeviceInfo {}

// cl_ext_float_atomics: device queries and the global-add capability bit.
const CL_DEVICE_SINGLE_FP_ATOMIC_CAPABILITIES_EXT: u32 = 0x4231;
const CL_DEVICE_DOUBLE_FP_ATOMIC_CAPABILITIES_EXT: u32 = 0x4232;
const CL_DEVICE_GLOBAL_FP_ATOMIC_ADD_EXT: u64 = 1 << 1;

/// Whether a cl_ext_float_atomics capability query reports a global atomic add.
fn fp_atomic_add(d: &Device, query: u32) -> bool {
    match d.get_data(query) {
        Ok(b) if b.len() == 8 => {
            let bits = u64::from_ne_bytes(b.try_into().unwrap_or([0; 8]));
            bits & CL_DEVICE_GLOBAL_FP_ATOMIC_ADD_EXT != 0
        }
        _ => false,
    }
}

/// Lists every device of every platform. No platform at all is an error that
/// says how to install PoCL.
pub fn list_devices() -> Result<Vec<DeviceInfo>> {
    let _guard = super::program::driver_lock();
    let platforms = get_platforms().map_err(|e| Error::NoPlatform {
        detail: e.to_string(),
    })?;
    if platforms.is_empty() {
        return Err(Error::NoPlatform {
            detail: "the ICD loader found no platform".into(),
        });
    }
    let mut out = Vec::new();
    for p in platforms {
        let pname = p.name().unwrap_or_default();
        let Ok(ids) = p.get_devices(CL_DEVICE_TYPE_ALL) else {
            continue;
        };
        for id in ids {
            let d = Device::new(id);
            let ext = d.extensions().unwrap_or_default();
            let has = |e: &str| ext.split_whitespace().any(|x| x == e);
            let ty = d.dev_type().unwrap_or(0);
            let kind = if ty & CL_DEVICE_TYPE_GPU != 0 {
                "GPU"
            } else if ty & CL_DEVICE_TYPE_CPU != 0 {
                "CPU"
            } else if ty & opencl3::device::CL_DEVICE_TYPE_ACCELERATOR != 0 {
                "ACCELERATOR"
            } else {
                "OTHER"
            };
            out.push(DeviceInfo {
                index: out.len(),
                platform: pname.trim().to_string(),
                name: d.name().unwrap_or_default().trim().to_string(),
                kind: kind.to_string(),
                version: d.version().unwrap_or_default().trim().to_string(),
                compute_units: d.max_compute_units().unwrap_or(0),
                global_mem: d.global_mem_size().unwrap_or(0),
                max_alloc: d.max_mem_alloc_size().unwrap_or(0),
                fp64: has("cl_khr_fp64"),
                gl_sharing: has("cl_khr_gl_sharing"),
                int64_atomics: has("cl_khr_int64_base_atomics"),
                float_atomics: has("cl_ext_float_atomics")
                    && fp_atomic_add(&d, CL_DEVICE_SINGLE_FP_ATOMIC_CAPABILITIES_EXT),
                double_atomics: has("cl_ext_float_atomics")
                    && fp_atomic_add(&d, CL_DEVICE_DOUBLE_FP_ATOMIC_CAPABILITIES_EXT),
                correctly_rounded_div_sqrt: d.single_fp_config().unwrap_or(0)
                    & opencl3::device::CL_FP_CORRECTLY_ROUNDED_DIVIDE_SQRT
                    != 0,
                ptx: pname.trim().starts_with("NVIDIA CUDA"),
                native_float_width: d.native_vector_width_float().unwrap_or(1),
                native_double_width: d.native_vector_width_double().unwrap_or(0),
                id,
            });
        }
    }
    if out.is_empty() {
        return Err(Error::NoPlatform {
            detail: "platforms exist but expose no device".into(),
        });
    }
    Ok(out)
}

/// Picks a device: `selector` (or `SHAPECUE_DEVICE`) as an index or a
/// case-insensitive substring of the platform's name (first), else of
/// "platform device" (so "intel" picks Intel's runtime rather than PoCL's
/// device named after an Intel processor); by default the first GPU,
/// else the first CPU device, else the first device.
pub fn select(selector: Option<&str>) -> Result<DeviceInfo> {
    let all = list_devices()?;
    let env = std::env::var("SHAPECUE_DEVICE").ok();
    let sel = selector
        .map(str::to_string)
        .or(env)
        .filter(|s| !s.trim().is_empty());
    pick(&all, sel.as_deref())
}

pub(crate) fn pick(all: &[DeviceInfo], sel: Option<&str>) -> Result<DeviceInfo> {
    let describe = || {
        all.iter()
            .map(|d| format!("{}: {} ({})", d.index, d.name, d.platform))
            .collect::<Vec<_>>()
            .join("; ")
    };
    match sel {
        Some(s) => {
            let s = s.trim();
            if let Ok(i) = s.parse::<usize>() {
                return all.get(i).cloned().ok_or_else(|| Error::NoDevice {
                    selector: s.to_string(),
                    available: describe(),
                });
            }
            let needle = s.to_lowercase();
            let has = |t: &str| t.to_lowercase().contains(&needle);
            all.iter()
                .find(|d| has(&d.platform))
                .or_else(|| {
                    all.iter()
                        .find(|d| has(&format!("{} {}", d.platform, d.name)))
                })
                .cloned()
                .ok_or_else(|| Error::NoDevice {
                    selector: s.to_string(),
                    available: describe(),
                })
        }
        None => Ok(all
            .iter()
            .find(|d| d.kind == "GPU")
            .or_else(|| all.iter().find(|d| d.kind == "CPU"))
            .unwrap_or(&all[0])
            .clone()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn dev(index: usize, kind: &str, name: &str) -> DeviceInfo {
        on("Plat", index, kind, name)
    }

    fn on(platform: &str, index: usize, kind: &str, name: &str) -> DeviceInfo {
        DeviceInfo {
            index,
            platform: platform.into(),
            name: name.into(),
            kind: kind.into(),
            version: String::new(),
            compute_units: 1,
            global_mem: 0,
            max_alloc: 0,
            fp64: false,
            gl_sharing: false,
            int64_atomics: false,
            float_atomics: false,
            double_atomics: false,
            correctly_rounded_div_sqrt: true,
            ptx: false,
            native_float_width: 1,
            native_double_width: 0,
            id: std::ptr::null_mut(),
        }
    }

    #[test]
    fn default_prefers_the_first_gpu_then_the_first_cpu() {
        let all = [
            dev(0, "CPU", "cpu a"),
            dev(1, "GPU", "gpu b"),
            dev(2, "GPU", "gpu c"),
        ];
        assert_eq!(pick(&all, None).unwrap().index, 1);
        let cpus = [dev(0, "ACCELERATOR", "acc"), dev(1, "CPU", "cpu")];
        assert_eq!(pick(&cpus, None).unwrap().index, 1);
        let other = [dev(0, "ACCELERATOR", "acc")];
        assert_eq!(pick(&other, None).unwrap().index, 0);
    }

    #[test]
    fn selector_is_an_index_or_a_name_substring() {
        let all = [
            dev(0, "CPU", "pthread-skylake"),
            dev(1, "GPU", "NVIDIA H100"),
        ];
        assert_eq!(pick(&all, Some("0")).unwrap().index, 0);
        assert_eq!(pick(&all, Some(" h100 ")).unwrap().index, 1);
        assert_eq!(pick(&all, Some("plat")).unwrap().index, 0);
        let e = pick(&all, Some("7")).unwrap_err().to_string();
        assert!(e.contains("'7'") && e.contains("1: NVIDIA H100"), "{e}");
        let e = pick(&all, Some("radeon")).unwrap_err().to_string();
        assert!(e.contains("radeon") && e.contains("available"), "{e}");
    }

    #[test]
    fn a_platform_name_wins_over_a_device_name() {
        // PoCL names its device after the processor: "intel" must still pick
        // Intel's runtime, listed after it.
        let all = [
            on(
                "Portable Computing Language",
                0,
                "CPU",
                "pthread-skylake-avx512-Intel(R) Xeon(R)",
            ),
            on("Intel(R) OpenCL", 1, "CPU", "Intel(R) Xeon(R) Processor"),
        ];
        assert_eq!(pick(&all, Some("intel")).unwrap().index, 1);
        assert_eq!(pick(&all, Some("portable")).unwrap().index, 0);
        assert_eq!(pick(&all, Some("skylake")).unwrap().index, 0);
        let pocl_only = [all[0].clone()];
        assert_eq!(pick(&pocl_only, Some("intel")).unwrap().index, 0);
    }
}
