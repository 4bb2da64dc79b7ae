//! Layout probes for the tests of the families that pass `#[repr(C)]`
//! structs to their kernels: what the device compiler sees of them.

use super::*;

/// Asserts that the device compiler lays out a family's `#[repr(C)]` structs
/// as Rust does: `fields` are `("Struct.field", offset)` and
/// `("Struct.(size)", size)`, as the families' `field_offsets` give them,
/// probed through [`probe_layout`].
pub(crate) fn check_layout(
    base: &KernelFile,
    options: &str,
    entry: impl crate::spec::kernels::KernelEntry,
    fields: &[(&str, usize)],
) {
    let exprs: Vec<String> = (fields.iter())
        .map(|(name, _)| match name.split_once('.') {
            Some((st, "(size)")) => format!("sizeof({st})"),
            Some((st, field)) => format!("__builtin_offsetof({st}, {field})"),
            None => panic!("{name}: expected struct.field"),
        })
        .collect();
    let got = probe_layout(base, options, entry, &exprs);
    for ((name, want), got) in fields.iter().zip(got) {
        assert_eq!(got as usize, *want, "{name}: device vs Rust");
    }
}

/// What the device compiler sees of a family's `#[repr(C)]` structs: a probe
/// kernel `entry` appended to `base` (built with `options`) writes the value
/// of each C expression (`sizeof(T)`, `__builtin_offsetof(T, f)`), read back
/// in order. The layout tests of the families that pass structs call it.
pub(crate) fn probe_layout(
    base: &KernelFile,
    options: &str,
    entry: impl crate::spec::kernels::KernelEntry,
    exprs: &[String],
) -> Vec<u32> {
    let gpu = test_gpu();
    let mut probe = format!("\n__kernel void {}(__global uint* out) {{\n", entry.entry());
    for (i, expr) in exprs.iter().enumerate() {
        probe += &format!("    out[{i}] = (uint)({expr});\n");
    }
    probe += "}\n";
    let file = KernelFile {
        name: Box::leak(format!("{} (layout probe)", base.name).into_boxed_str()),
        source: Box::leak((base.source.to_string() + &probe).into_boxed_str()),
        ..*base
    };
    let prog = gpu.program(&file, options).unwrap();
    let k = gpu.entry(&prog, entry).unwrap();
    let mut out: Buffer<u32> = gpu.buffer(exprs.len()).unwrap();
    gpu.write(&mut out, &vec![u32::MAX; exprs.len()]).unwrap();
    launch(&gpu, &k, 1, &[buf(&out)]).unwrap();
    gpu.finish().unwrap();
    let mut got = vec![0u32; exprs.len()];
    gpu.read(&out, &mut got).unwrap();
    got
}
