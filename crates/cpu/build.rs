//! Rebuilds pathlight-cpu when the profile that `tools/rustc-pgo` compiles its optimised builds
//! with changes, or the variable that chooses it.

fn main() {
    println!("cargo::rerun-if-changed=../../pgo/pathlight-cpu.profdata");
    println!("cargo::rerun-if-changed=../../pgo/llvm-version");
    println!("cargo::rerun-if-env-changed=PATHLIGHT_PGO");
    println!("cargo::rustc-check-cfg=cfg(pathlight_pgo_stand_in)");
}
