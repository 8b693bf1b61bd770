//! `lodbench list`: the scenes, the methods and the adapters.

use crate::error::Result;
use crate::gpu;
use crate::methods;
use crate::scene::SceneKind;

/// Prints the scenes, the methods with what each does, and the adapters found (best first), each after its
/// index (what `--adapter INDEX` names).
pub fn execute() -> Result<()> {
    outln!(
        "scenes:  {}, or a glTF file of your own (--scene PATH.gltf or PATH.glb)",
        SceneKind::names().join(", ")
    );
    outln!("methods:");
    for m in methods::BUILTIN {
        outln!("  {:<16} {}", m.name, m.about);
    }
    let adapters = gpu::context::enumerate_adapters();
    if adapters.is_empty() {
        outln!("adapters: none found");
        outln!("  {}", gpu::context::NO_ADAPTER_HELP);
        return Ok(());
    }
    outln!("adapters (best first; `--adapter INDEX` or `--adapter SUBSTRING` picks one):");
    for (index, a) in adapters.iter().enumerate() {
        let i = a.get_info();
        let ts = a.features().contains(wgpu::Features::TIMESTAMP_QUERY);
        outln!(
            "  {index}  {}  [{:?}, {:?}, driver {} {}{}]",
            i.name,
            i.backend,
            i.device_type,
            i.driver,
            i.driver_info,
            if ts { ", timestamps" } else { "" }
        );
    }
    Ok(())
}
