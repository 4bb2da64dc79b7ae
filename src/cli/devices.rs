//! `shapecue devices`: the OpenCL platforms and devices, as a table or JSON.

use super::out;
use anyhow::Result;
use shapecue::api::{Gpu, list_devices};

/// Lists the devices; `*` marks the one a command would use: `device` (which
/// must exist) or the default.
pub fn run(device: Option<&str>, json: bool) -> Result<()> {
    let devs = list_devices()?;
    // A device given with --device (or SHAPECUE_DEVICE) must exist: it is
    // the one marked, in place of the default.
    let chosen = match device {
        Some(d) => Some(Gpu::new(Some(d))?.info.index),
        None => None,
    };
    if json {
        out!("{}", serde_json::to_string_pretty(&devs)?);
        return Ok(());
    }
    let default = chosen.or_else(|| Gpu::new(None).ok().map(|g| g.info.index));
    out!(
        "{:>3}  {:<4} {:>3} {:>9} {:>4} {:>10} {:>9} {:>10} {:>5}  platform / device",
        "#",
        "type",
        "CUs",
        "memory",
        "fp64",
        "gl_sharing",
        "int64_atm",
        "float_atm",
        "lanes"
    );
    let yn = |b: bool| if b { "yes" } else { "no" };
    for d in devs {
        out!(
            "{:>3}{} {:<4} {:>3} {:>6} MiB {:>4} {:>10} {:>9} {:>10} {:>5}  {} / {} ({})",
            d.index,
            if Some(d.index) == default { "*" } else { " " },
            d.kind,
            d.compute_units,
            d.global_mem >> 20,
            yn(d.fp64),
            yn(d.gl_sharing),
            yn(d.int64_atomics),
            match (d.float_atomics, d.double_atomics) {
                (true, true) => "f32 f64",
                (true, false) => "f32",
                (false, true) => "f64",
                (false, false) => "no",
            },
            shapecue::spec::curvature::face_lanes_for(
                shapecue::spec::curvature::Lanes::Auto,
                &d.kind,
                d.native_float_width
            ),
            d.platform,
            d.name,
            d.version
        );
    }
    out!("(* = default; choose with --device <index|name> or SHAPECUE_DEVICE)");
    Ok(())
}
