//! Vulkan for one job: allocations exported as opaque file descriptors
//! (`VK_KHR_external_memory_fd`), which OpenCL
//! (`cl_khr_external_memory_opaque_fd`, [`super::external`]) and GL
//! (`GL_EXT_memory_object_fd`, `render::external`) import, so that kernels
//! write the memory GL draws from.
//!
//! The Vulkan loader is found at run time (`ash::Entry::load`): a machine
//! without `libvulkan.so.1` builds and runs as before and simply has no
//! external-memory route ([`probe`] says why).
//!
//! One [`VulkanExporter`] holds an instance and a logical device; each
//! [`ExportedBuffer`] holds a buffer and its memory and keeps the device
//! alive, so they are freed in order (buffer and memory, then device, then
//! instance) whatever drops first. Calls in order, as verified on an NVIDIA
//! H200: a buffer created with `VkExternalMemoryBufferCreateInfo` (opaque
//! fd), memory allocated with `VkExportMemoryAllocateInfo` (opaque fd),
//! then `vkGetMemoryFdKHR` once per importer (each import owns its fd).

use std::os::fd::{FromRawFd, OwnedFd};
use std::sync::Arc;

use ash::vk;

use crate::error::{Error, Result};

fn vk_err(what: &str) -> impl Fn(vk::Result) -> Error + '_ {
    move |e| Error::Vulkan {
        what: what.to_string(),
        detail: e.to_string(),
    }
}

/// A Vulkan physical device that can export opaque fds.
#[derive(Clone, Debug, PartialEq, Eq, serde::Serialize)]
pub struct VulkanDeviceInfo {
    /// `VkPhysicalDeviceProperties::deviceName`.
    pub name: String,
    /// `VkPhysicalDeviceIDProperties::deviceUUID` (GL's `GL_DEVICE_UUID_EXT`
    /// and OpenCL's `CL_DEVICE_UUID_KHR` name the same device by it).
    pub uuid: [u8; 16],
}

/// Loader, instance and the physical devices that report
/// `VK_KHR_external_memory_fd` (with Vulkan ≥ 1.1, where external memory
/// is core); the instance is destroyed by the caller.
struct Found {
    entry: ash::Entry,
    instance: ash::Instance,
    devices: Vec<(vk::PhysicalDevice, VulkanDeviceInfo)>,
}

fn find() -> std::result::Result<Found, String> {
    // SAFETY: loads the system's Vulkan loader, which implements the API.
    let entry = unsafe { ash::Entry::load() }.map_err(|e| format!("no Vulkan loader: {e}"))?;
    let app = vk::ApplicationInfo::default()
        .application_name(c"shapecue")
        .api_version(vk::API_VERSION_1_1);
    let info = vk::InstanceCreateInfo::default().application_info(&app);
    // SAFETY: `info` and what it points to outlive the call.
    let instance = unsafe { entry.create_instance(&info, None) }
        .map_err(|e| format!("vkCreateInstance failed: {e}"))?;
    // SAFETY: the instance is valid; every query below reads into owned structs.
    let devices = unsafe {
        let all = instance.enumerate_physical_devices().unwrap_or_default();
        let mut found = Vec::new();
        for pd in all {
            let props = instance.get_physical_device_properties(pd);
            if props.api_version < vk::API_VERSION_1_1 {
                continue;
            }
            let exts = instance
                .enumerate_device_extension_properties(pd)
                .unwrap_or_default();
            let has = exts.iter().any(|e| {
                e.extension_name_as_c_str()
                    .is_ok_and(|n| n == ash::khr::external_memory_fd::NAME)
            });
            if !has {
                continue;
            }
            let mut id = vk::PhysicalDeviceIDProperties::default();
            let mut p2 = vk::PhysicalDeviceProperties2::default().push_next(&mut id);
            instance.get_physical_device_properties2(pd, &mut p2);
            let name = props
                .device_name_as_c_str()
                .map(|n| n.to_string_lossy().into_owned())
                .unwrap_or_default();
            found.push((
                pd,
                VulkanDeviceInfo {
                    name,
                    uuid: id.device_uuid,
                },
            ));
        }
        found
    };
    Ok(Found {
        entry,
        instance,
        devices,
    })
}

/// The Vulkan devices that can export opaque fds, or why there are none
/// (no loader, no driver, no device with the extension), in words.
pub fn probe() -> std::result::Result<Vec<VulkanDeviceInfo>, String> {
    let found = find()?;
    // SAFETY: nothing was created from the instance but queries.
    unsafe { found.instance.destroy_instance(None) };
    let list: Vec<_> = found.devices.into_iter().map(|(_, d)| d).collect();
    if list.is_empty() {
        return Err("no Vulkan 1.1 device reports VK_KHR_external_memory_fd".into());
    }
    Ok(list)
}

/// The instance, device and extension functions an exporter and its
/// buffers share; destroyed when the last of them is dropped.
struct Inner {
    _entry: ash::Entry,
    instance: ash::Instance,
    device: ash::Device,
    memory_fd: ash::khr::external_memory_fd::Device,
    memory: vk::PhysicalDeviceMemoryProperties,
    info: VulkanDeviceInfo,
}

impl Drop for Inner {
    fn drop(&mut self) {
        // SAFETY: every buffer and allocation holds an Arc of this, so none
        // is left; the device is idle (nothing is ever submitted).
        unsafe {
            self.device.destroy_device(None);
            self.instance.destroy_instance(None);
        }
    }
}

/// A Vulkan device that makes exportable buffers.
pub struct VulkanExporter {
    inner: Arc<Inner>,
}

impl VulkanExporter {
    /// Opens the device whose UUID is `uuid` (the GPU that GL and OpenCL run
    /// on), or the first that exports opaque fds when `uuid` is `None`.
    ///
    /// # Errors
    /// [`Error::Vulkan`] without a loader, without such a device, or when
    /// the device cannot be created.
    pub fn new(uuid: Option<[u8; 16]>) -> Result<VulkanExporter> {
        let found = find().map_err(|detail| Error::Vulkan {
            what: "loading Vulkan".into(),
            detail,
        })?;
        let pick = found
            .devices
            .iter()
            .find(|(_, d)| uuid.is_none_or(|u| u == d.uuid))
            .cloned();
        let Some((pd, info)) = pick else {
            // SAFETY: nothing was created from the instance but queries.
            unsafe { found.instance.destroy_instance(None) };
            return Err(Error::Vulkan {
                what: "choosing a device".into(),
                detail: format!(
                    "no Vulkan 1.1 device with VK_KHR_external_memory_fd {}",
                    if uuid.is_some() {
                        "has the GL context's device UUID"
                    } else {
                        "was found"
                    }
                ),
            });
        };
        let instance = found.instance;
        let priorities = [1.0f32];
        // Memory only: any queue family will do, the device needs one.
        let queue = [vk::DeviceQueueCreateInfo::default()
            .queue_family_index(0)
            .queue_priorities(&priorities)];
        let exts: [*const std::ffi::c_char; 1] = [ash::khr::external_memory_fd::NAME.as_ptr()];
        let info_dev = vk::DeviceCreateInfo::default()
            .queue_create_infos(&queue)
            .enabled_extension_names(&exts);
        // SAFETY: `pd` came from this instance; the create info outlives the call.
        let device = match unsafe { instance.create_device(pd, &info_dev, None) } {
            Ok(d) => d,
            Err(e) => {
                // SAFETY: no device was made.
                unsafe { instance.destroy_instance(None) };
                return Err(vk_err("vkCreateDevice")(e));
            }
        };
        let memory_fd = ash::khr::external_memory_fd::Device::new(&instance, &device);
        // SAFETY: `pd` is a physical device of this instance.
        let memory = unsafe { instance.get_physical_device_memory_properties(pd) };
        Ok(VulkanExporter {
            inner: Arc::new(Inner {
                _entry: found.entry,
                instance,
                device,
                memory_fd,
                memory,
                info,
            }),
        })
    }

    /// The device's name and UUID.
    pub fn info(&self) -> &VulkanDeviceInfo {
        &self.inner.info
    }

    /// A buffer of `size` bytes (> 0) whose memory can be exported as opaque
    /// fds: device-local, and also host-visible when `host_visible` (so that
    /// [`ExportedBuffer::write`] can fill it; tests do).
    ///
    /// # Errors
    /// [`Error::Vulkan`] when the buffer or its memory cannot be made, or no
    /// memory type fits.
    pub fn export(&self, size: u64, host_visible: bool) -> Result<ExportedBuffer> {
        if size == 0 {
            return Err(Error::InvalidArgument(
                "an exported Vulkan buffer needs at least one byte".into(),
            ));
        }
        // Whole 64 KiB blocks: Mesa's llvmpipe refuses GL buffers on small
        // imported allocations (GL_OUT_OF_MEMORY at 192 bytes, fine at 64 KiB),
        // and GPUs allocate in such blocks anyway.
        let block = 1u64 << 16;
        let padded = size.div_ceil(block).saturating_mul(block);
        let d = &self.inner.device;
        let opaque = vk::ExternalMemoryHandleTypeFlags::OPAQUE_FD;
        let mut ext_info = vk::ExternalMemoryBufferCreateInfo::default().handle_types(opaque);
        let info = vk::BufferCreateInfo::default()
            .size(padded)
            .usage(
                vk::BufferUsageFlags::STORAGE_BUFFER
                    | vk::BufferUsageFlags::VERTEX_BUFFER
                    | vk::BufferUsageFlags::TRANSFER_SRC
                    | vk::BufferUsageFlags::TRANSFER_DST,
            )
            .sharing_mode(vk::SharingMode::EXCLUSIVE)
            .push_next(&mut ext_info);
        // SAFETY: the device is valid; `info` outlives the call.
        let buffer = unsafe { d.create_buffer(&info, None) }.map_err(vk_err("vkCreateBuffer"))?;
        let mut out = ExportedBuffer {
            inner: self.inner.clone(),
            buffer,
            memory: vk::DeviceMemory::null(),
            size,
            allocation: 0,
            host_visible,
        };
        // SAFETY: `buffer` was made on this device.
        let req = unsafe { d.get_buffer_memory_requirements(buffer) };
        let want = if host_visible {
            vk::MemoryPropertyFlags::HOST_VISIBLE | vk::MemoryPropertyFlags::HOST_COHERENT
        } else {
            vk::MemoryPropertyFlags::DEVICE_LOCAL
        };
        let mem = &self.inner.memory;
        let Some(type_index) = (0..mem.memory_type_count).find(|&i| {
            req.memory_type_bits & (1 << i) != 0
                && mem.memory_types[i as usize].property_flags.contains(want)
        }) else {
            return Err(Error::Vulkan {
                what: "choosing a memory type".into(),
                detail: "no memory type of the buffer has the properties it needs".into(),
            });
        };
        let mut export = vk::ExportMemoryAllocateInfo::default().handle_types(opaque);
        let alloc = vk::MemoryAllocateInfo::default()
            .allocation_size(req.size)
            .memory_type_index(type_index)
            .push_next(&mut export);
        // SAFETY: as above; on error `out` drops and destroys the buffer.
        out.memory =
            unsafe { d.allocate_memory(&alloc, None) }.map_err(vk_err("vkAllocateMemory"))?;
        out.allocation = req.size;
        // SAFETY: the memory was allocated for this buffer's requirements.
        unsafe { d.bind_buffer_memory(buffer, out.memory, 0) }
            .map_err(vk_err("vkBindBufferMemory"))?;
        Ok(out)
    }
}

/// A Vulkan buffer and its exportable memory; see [`VulkanExporter::export`].
pub struct ExportedBuffer {
    inner: Arc<Inner>,
    buffer: vk::Buffer,
    memory: vk::DeviceMemory,
    size: u64,
    allocation: u64,
    host_visible: bool,
}

impl ExportedBuffer {
    /// The buffer's size in bytes, as asked for (the buffer itself is
    /// rounded up to whole 64 KiB blocks).
    pub fn size(&self) -> u64 {
        self.size
    }

    /// The allocation's size in bytes (≥ [`size`](Self::size)): what an
    /// importer is told the memory object holds.
    pub fn allocation_size(&self) -> u64 {
        self.allocation
    }

    /// A new opaque fd of the memory (`vkGetMemoryFdKHR`), for one importer;
    /// the importer takes it over (GL and OpenCL close it themselves once
    /// the import succeeds).
    ///
    /// # Errors
    /// [`Error::Vulkan`] when the driver gives no fd.
    pub fn fd(&self) -> Result<OwnedFd> {
        let info = vk::MemoryGetFdInfoKHR::default()
            .memory(self.memory)
            .handle_type(vk::ExternalMemoryHandleTypeFlags::OPAQUE_FD);
        // SAFETY: the memory was allocated exportable as opaque fds.
        let fd = unsafe { self.inner.memory_fd.get_memory_fd(&info) }
            .map_err(vk_err("vkGetMemoryFdKHR"))?;
        if fd < 0 {
            return Err(Error::Vulkan {
                what: "vkGetMemoryFdKHR".into(),
                detail: format!("returned fd {fd}"),
            });
        }
        // SAFETY: vkGetMemoryFdKHR hands the caller a new fd it owns.
        Ok(unsafe { OwnedFd::from_raw_fd(fd) })
    }

    /// Writes `bytes` at `offset` through a mapping (host-visible buffers only).
    ///
    /// # Errors
    /// [`Error::InvalidArgument`] for a device-only buffer or a range past
    /// the end; [`Error::Vulkan`] when mapping fails.
    pub fn write(&self, offset: u64, bytes: &[u8]) -> Result<()> {
        let end = offset.checked_add(bytes.len() as u64);
        if !self.host_visible || end.is_none_or(|e| e > self.size) {
            return Err(Error::InvalidArgument(format!(
                "writing {} bytes at {offset} into a {}-byte exported buffer{}",
                bytes.len(),
                self.size,
                if self.host_visible {
                    ""
                } else {
                    " that the host cannot map"
                }
            )));
        }
        if bytes.is_empty() {
            return Ok(());
        }
        let d = &self.inner.device;
        // SAFETY: host-visible, coherent memory; the range lies inside it, and
        // the copy ends before the unmap.
        unsafe {
            let p = d
                .map_memory(
                    self.memory,
                    offset,
                    bytes.len() as u64,
                    vk::MemoryMapFlags::empty(),
                )
                .map_err(vk_err("vkMapMemory"))?;
            std::ptr::copy_nonoverlapping(bytes.as_ptr(), p.cast::<u8>(), bytes.len());
            d.unmap_memory(self.memory);
        }
        Ok(())
    }
}

impl Drop for ExportedBuffer {
    fn drop(&mut self) {
        let d = &self.inner.device;
        // SAFETY: made on this device, used by no submitted work (nothing is
        // submitted); importers hold their own references to the memory.
        unsafe {
            d.destroy_buffer(self.buffer, None);
            if self.memory != vk::DeviceMemory::null() {
                d.free_memory(self.memory, None);
            }
        }
    }
}
