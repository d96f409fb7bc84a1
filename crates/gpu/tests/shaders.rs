//! Every WGSL file in `shaders/` parses and validates with naga, in f64 (with the
//! `FLOAT64` capability) and in the f32 variant, without a GPU. New shader files are
//! picked up by iterating the directory.

use std::path::Path;

use naga::valid::{Capabilities, ValidationFlags, Validator};
use winslow_gpu::{shader_source, Precision, ASSEMBLY_WGSL, DET_J_WGSL, F64_ALIAS, MULTIGRID_WGSL, PACK_WGSL};

fn validate(name: &str, src: &str, caps: Capabilities) -> naga::Module {
    let module = naga::front::wgsl::parse_str(src).unwrap_or_else(|e| panic!("{name}: {}", e.emit_to_string(src)));
    Validator::new(ValidationFlags::all(), caps)
        .validate(&module)
        .unwrap_or_else(|e| panic!("{name}: {}", e.emit_to_string(src)));
    module
}

fn shader_files() -> Vec<std::path::PathBuf> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../shaders");
    let mut files: Vec<_> = std::fs::read_dir(&dir)
        .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
        .map(|e| e.expect("directory entry").path())
        .filter(|p| p.extension().is_some_and(|x| x == "wgsl"))
        .collect();
    files.sort();
    files
}

#[test]
fn every_shader_validates_in_f64_and_f32() {
    let files = shader_files();
    assert!(files.len() >= 2, "expected the shaders in shaders/, found {files:?}");
    for path in files {
        let name = path.display().to_string();
        let src = std::fs::read_to_string(&path).expect("readable shader");
        assert!(src.starts_with(F64_ALIAS), "{name}: must start with the precision line `{F64_ALIAS}`");
        let m = validate(&name, &src, Capabilities::FLOAT64);
        assert!(m.entry_points.iter().all(|e| e.stage == naga::ShaderStage::Compute), "{name}: compute only");
        let f32_src = shader_source(&src, Precision::F32);
        assert!(!f32_src.contains("f64"), "{name}: the f32 variant still mentions f64");
        // the f32 variant needs no FLOAT64 capability
        validate(&format!("{name} (f32)"), &f32_src, Capabilities::empty());
    }
}

#[test]
fn f64_shaders_need_the_float64_capability() {
    // The validator must reject f64 without the capability: shows that the f64 test
    // above really checks something about precision.
    let module = naga::front::wgsl::parse_str(ASSEMBLY_WGSL).expect("parses");
    assert!(Validator::new(ValidationFlags::all(), Capabilities::empty()).validate(&module).is_err());
}

#[test]
fn embedded_sources_are_the_files() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../shaders");
    assert_eq!(std::fs::read_to_string(dir.join("assembly.wgsl")).unwrap(), ASSEMBLY_WGSL);
    assert_eq!(std::fs::read_to_string(dir.join("det_j.wgsl")).unwrap(), DET_J_WGSL);
    assert_eq!(std::fs::read_to_string(dir.join("multigrid.wgsl")).unwrap(), MULTIGRID_WGSL);
    assert_eq!(std::fs::read_to_string(dir.join("pack.wgsl")).unwrap(), PACK_WGSL);
    let pack = validate("pack", PACK_WGSL, Capabilities::FLOAT64);
    assert!(pack.entry_points.iter().any(|e| e.name == "pack"), "pack.wgsl lacks entry point pack");
    let multigrid: Vec<String> = validate("multigrid", MULTIGRID_WGSL, Capabilities::FLOAT64)
        .entry_points
        .iter()
        .map(|e| e.name.clone())
        .collect();
    for e in ["residual", "line_smooth", "transfer_rows", "transfer_cols", "coarse_solve"] {
        assert!(multigrid.iter().any(|n| n == e), "multigrid.wgsl lacks entry point {e}: {multigrid:?}");
    }
    let entries: Vec<String> = validate("assembly", ASSEMBLY_WGSL, Capabilities::FLOAT64)
        .entry_points
        .iter()
        .map(|e| e.name.clone())
        .collect();
    for e in ["geometry", "egg_residual", "egg_stencil", "elasticity_stencil", "mass_stencil"] {
        assert!(entries.iter().any(|n| n == e), "assembly.wgsl lacks entry point {e}: {entries:?}");
    }
}
