//! The headless device: adapter choice, device creation, and GPU errors turned into `Error`s.

use crate::error::{Error, Result};
use serde::Serialize;
use std::sync::{Arc, Mutex};

/// The adapter facts recorded in run.json and printed by `lodbench list`.
#[derive(Debug, Clone, Serialize)]
pub struct AdapterSummary {
    /// The adapter's place (0-based) in the list [`enumerate_adapters`] returns and `lodbench list` prints:
    /// what `--adapter INDEX` names.
    pub index: usize,
    pub name: String,
    pub backend: String,
    pub device_type: String,
    pub driver: String,
    pub driver_info: String,
}

impl AdapterSummary {
    /// The facts of the `index`-th adapter of [`enumerate_adapters`].
    pub fn new(index: usize, i: &wgpu::AdapterInfo) -> Self {
        AdapterSummary {
            index,
            name: i.name.clone(),
            backend: format!("{:?}", i.backend).to_lowercase(),
            device_type: format!("{:?}", i.device_type),
            driver: i.driver.clone(),
            driver_info: i.driver_info.clone(),
        }
    }
}

/// How frame times are taken.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum TimingSource {
    /// GPU timestamp queries around all of a frame's passes.
    GpuTimestamps,
    /// No timestamps on this adapter: only the CPU clock from encoding to completion.
    CpuClock,
}

pub const NO_ADAPTER_HELP: &str = "no GPU adapter found (lodbench needs Vulkan, Metal or DX12). \
On a machine without a GPU install a software Vulkan driver, e.g. on Debian/Ubuntu: \
`sudo apt-get install mesa-vulkan-drivers libvulkan1` (Mesa lavapipe)";

pub struct GpuContext {
    pub adapter: wgpu::Adapter,
    pub device: wgpu::Device,
    pub queue: wgpu::Queue,
    pub info: AdapterSummary,
    pub timing: TimingSource,
    /// Nanoseconds per timestamp tick.
    pub timestamp_period_ns: f32,
    errors: Arc<Mutex<Vec<String>>>,
}

fn instance() -> wgpu::Instance {
    let mut desc = wgpu::InstanceDescriptor::new_without_display_handle_from_env();
    desc.backends = wgpu::Backends::VULKAN | wgpu::Backends::METAL | wgpu::Backends::DX12;
    wgpu::Instance::new(desc)
}

fn type_rank(t: wgpu::DeviceType) -> u8 {
    match t {
        wgpu::DeviceType::DiscreteGpu => 0,
        wgpu::DeviceType::IntegratedGpu => 1,
        wgpu::DeviceType::VirtualGpu => 2,
        wgpu::DeviceType::Cpu => 3,
        wgpu::DeviceType::Other => 4,
    }
}

/// Every adapter wgpu finds, best first (discrete, integrated, virtual, CPU).
pub fn enumerate_adapters() -> Vec<wgpu::Adapter> {
    let _driver = driver_lock();
    enumerate_unlocked()
}

/// One driver initialisation at a time in this process: instance creation, adapter enumeration and device
/// creation from several threads at once have crashed drivers (wgpu issues 10010 and 10234; an intermittent
/// SIGSEGV in libc's allocator during the parallel integration tests on lavapipe). The lock is held only while a
/// context is made, never while it renders.
fn driver_lock() -> std::sync::MutexGuard<'static, ()> {
    static DRIVER: Mutex<()> = Mutex::new(());
    DRIVER
        .lock()
        .unwrap_or_else(|poisoned| poisoned.into_inner())
}

fn enumerate_unlocked() -> Vec<wgpu::Adapter> {
    let inst = instance();
    let mut adapters = pollster::block_on(inst.enumerate_adapters(wgpu::Backends::all()));
    adapters.sort_by_key(|a| type_rank(a.get_info().device_type));
    adapters
}

/// The adapter `--adapter` names among `found` (as [`enumerate_adapters`] lists them, best first): an index
/// (a whole number, 0-based, the order `lodbench list` prints), or else the first whose name contains the text
/// (case-insensitive); the best one (index 0) without the flag. `found` must not be empty.
pub fn choose_adapter(found: &[AdapterSummary], spec: Option<&str>) -> Result<usize> {
    let listing = || {
        found
            .iter()
            .enumerate()
            .map(|(i, a)| format!("{i} {}", a.name))
            .collect::<Vec<_>>()
            .join(", ")
    };
    let Some(spec) = spec.map(str::trim) else {
        return Ok(0);
    };
    if let Ok(index) = spec.parse::<usize>() {
        return if index < found.len() {
            Ok(index)
        } else {
            Err(Error::NoAdapter(format!(
                "--adapter {index}: no adapter has index {index}; found {} (0-based, as `lodbench list` \
                 prints them): {}",
                found.len(),
                listing()
            )))
        };
    }
    let needle = spec.to_lowercase();
    found
        .iter()
        .position(|a| a.name.to_lowercase().contains(&needle))
        .ok_or_else(|| {
            Error::NoAdapter(format!(
                "--adapter {spec}: no adapter name contains '{spec}'; found: {}",
                listing()
            ))
        })
}

impl GpuContext {
    /// Opens the adapter `--adapter` names ([`choose_adapter`]: an index or a part of a name), or the best.
    pub fn new(spec: Option<&str>) -> Result<GpuContext> {
        let driver = driver_lock();
        let adapters = enumerate_unlocked();
        if adapters.is_empty() {
            return Err(Error::NoAdapter(NO_ADAPTER_HELP.into()));
        }
        let found: Vec<AdapterSummary> = adapters
            .iter()
            .enumerate()
            .map(|(i, a)| AdapterSummary::new(i, &a.get_info()))
            .collect();
        let index = choose_adapter(&found, spec)?;
        let adapter = adapters[index].clone();
        let info = adapter.get_info();
        let timestamps = adapter.features().contains(wgpu::Features::TIMESTAMP_QUERY);
        // Pipeline statistics count the fragment shader invocations of the quality pass's method frames
        // (summary.csv's `fragments_*` columns); never used in a timed frame.
        let wanted = wgpu::Features::TIMESTAMP_QUERY | wgpu::Features::PIPELINE_STATISTICS_QUERY;
        let required_features = adapter.features() & wanted;
        let (device, queue) = pollster::block_on(adapter.request_device(&wgpu::DeviceDescriptor {
            label: Some("lodbench device"),
            required_features,
            required_limits: adapter.limits(),
            experimental_features: wgpu::ExperimentalFeatures::disabled(),
            memory_hints: wgpu::MemoryHints::Performance,
            trace: wgpu::Trace::Off,
        }))
        .map_err(|e| Error::Gpu(format!("cannot open a device on {}: {e}", info.name)))?;
        let errors = Arc::new(Mutex::new(Vec::new()));
        let sink = errors.clone();
        device.on_uncaptured_error(Arc::new(move |e: wgpu::Error| {
            if let Ok(mut v) = sink.lock() {
                // wgpu's messages span lines; keep them to one.
                let text = e.to_string();
                v.push(text.split_whitespace().collect::<Vec<_>>().join(" "));
            }
        }));
        let timestamp_period_ns = queue.get_timestamp_period();
        drop(driver);
        Ok(GpuContext {
            info: found[index].clone(),
            adapter,
            device,
            queue,
            timing: if timestamps {
                TimingSource::GpuTimestamps
            } else {
                TimingSource::CpuClock
            },
            timestamp_period_ns,
            errors,
        })
    }

    /// Turns any GPU validation or out-of-memory error reported so far into an `Error`.
    pub fn check_errors(&self) -> Result<()> {
        let mut v = self
            .errors
            .lock()
            .map_err(|_| Error::Gpu("error log poisoned".into()))?;
        if v.is_empty() {
            Ok(())
        } else {
            let first = v.remove(0);
            let more = v.len();
            v.clear();
            Err(Error::Gpu(if more > 0 {
                format!("{first} (and {more} more)")
            } else {
                first
            }))
        }
    }

    /// Blocks until all submitted work is done.
    pub fn wait_idle(&self) -> Result<()> {
        self.device
            .poll(wgpu::PollType::wait_indefinitely())
            .map_err(|e| Error::Gpu(format!("waiting for the GPU: {e}")))?;
        self.check_errors()
    }

    /// Checks that a viewport fits this device.
    pub fn check_viewport(&self, width: u32, height: u32) -> Result<()> {
        let max = self.device.limits().max_texture_dimension_2d;
        if width > max || height > max {
            return Err(Error::Config(format!(
                "viewport {width}x{height} exceeds this adapter's largest texture side {max}"
            )));
        }
        Ok(())
    }

    /// Maps `buffer` for reading, waits, and hands its bytes to `f`.
    /// The first `count` 64-bit sums of a kernel's `sums` buffer, each stored as two u32 words (low, high)
    /// that shaders add with a carry: copied into the mappable `readback` (at least as large) and read.
    pub fn read_u64_sums(
        &self,
        sums: &wgpu::Buffer,
        readback: &wgpu::Buffer,
        count: usize,
    ) -> Result<Vec<u64>> {
        let mut encoder = self.device.create_command_encoder(&Default::default());
        encoder.copy_buffer_to_buffer(sums, 0, readback, 0, None);
        self.queue.submit([encoder.finish()]);
        self.read_buffer(readback, |bytes| {
            let words: &[u32] = bytemuck::cast_slice(bytes);
            words
                .chunks_exact(2)
                .take(count)
                .map(|w| w[0] as u64 | (w[1] as u64) << 32)
                .collect()
        })
    }

    pub fn read_buffer<T>(&self, buffer: &wgpu::Buffer, f: impl FnOnce(&[u8]) -> T) -> Result<T> {
        let (tx, rx) = std::sync::mpsc::channel();
        buffer.map_async(wgpu::MapMode::Read, .., move |r| {
            let _ = tx.send(r);
        });
        self.wait_idle()?;
        rx.recv()
            .map_err(|_| Error::Gpu("buffer map callback never ran".into()))?
            .map_err(|e| Error::Gpu(format!("mapping a read-back buffer: {e}")))?;
        let out = {
            let view = buffer
                .get_mapped_range(..)
                .map_err(|e| Error::Gpu(format!("reading a mapped buffer: {e:?}")))?;
            f(&view)
        };
        buffer.unmap();
        Ok(out)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn found(names: &[&str]) -> Vec<AdapterSummary> {
        names
            .iter()
            .enumerate()
            .map(|(index, n)| AdapterSummary {
                index,
                name: n.to_string(),
                backend: "vulkan".into(),
                device_type: "DiscreteGpu".into(),
                driver: String::new(),
                driver_info: String::new(),
            })
            .collect()
    }

    #[test]
    fn an_index_or_a_name_chooses_the_adapter() {
        // A node of identical GPUs: names cannot tell them apart, indices can.
        let f = found(&["NVIDIA H100", "NVIDIA H100", "llvmpipe (LLVM 19)"]);
        assert_eq!(choose_adapter(&f, None).unwrap(), 0);
        assert_eq!(choose_adapter(&f, Some("1")).unwrap(), 1);
        assert_eq!(choose_adapter(&f, Some(" 2 ")).unwrap(), 2);
        assert_eq!(choose_adapter(&f, Some("h100")).unwrap(), 0);
        assert_eq!(choose_adapter(&f, Some("LLVMpipe")).unwrap(), 2);
    }

    #[test]
    fn an_index_out_of_range_names_the_flag_the_index_and_the_adapters() {
        let f = found(&["NVIDIA H100", "NVIDIA H100"]);
        let e = choose_adapter(&f, Some("2")).unwrap_err().to_string();
        for needle in [
            "--adapter 2",
            "index 2",
            "found 2",
            "0 NVIDIA H100",
            "1 NVIDIA H100",
        ] {
            assert!(e.contains(needle), "'{needle}' not in: {e}");
        }
        let e = choose_adapter(&f, Some("radeon")).unwrap_err().to_string();
        assert!(
            e.contains("--adapter radeon") && e.contains("0 NVIDIA H100"),
            "{e}"
        );
        // A negative number is no index: it is looked for in the names.
        assert!(choose_adapter(&f, Some("-1")).is_err());
    }
}
