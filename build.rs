//! Records the git commit (when built from a checkout) for run.json.
use std::process::Command;

fn main() {
    println!("cargo:rerun-if-changed=.git/HEAD");
    println!("cargo:rerun-if-changed=.git/index");
    // An edited source makes the build dirty: without these, `--dirty` was computed only when HEAD or the index
    // changed, and a run from an edited tree recorded the clean parent commit.
    for path in [
        "src",
        "shaders",
        "scenes",
        "Cargo.toml",
        "Cargo.lock",
        "build.rs",
    ] {
        println!("cargo:rerun-if-changed={path}");
    }
    let commit = Command::new("git")
        .args(["describe", "--always", "--dirty", "--abbrev=12"])
        .output()
        .ok()
        .filter(|o| o.status.success())
        .map(|o| String::from_utf8_lossy(&o.stdout).trim().to_string())
        .unwrap_or_default();
    println!("cargo:rustc-env=LODBENCH_GIT_COMMIT={commit}");
}
