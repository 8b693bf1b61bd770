//! Records the git commit (when built from a checkout) for run.json, and, for a tree with uncommitted changes,
//! a hash of those changes to the build's sources (`lodbench merge` and `experiment --resume` compare it).
use std::process::Command;

/// What the binary is built from: an uncommitted change elsewhere (docs, tests) makes `git describe --dirty`
/// say dirty, but not the binary another.
const SOURCES: [&str; 6] = [
    "src",
    "shaders",
    "scenes",
    "Cargo.toml",
    "Cargo.lock",
    "build.rs",
];

fn main() {
    // The commit: HEAD, and the branch it points at (a commit moves the branch, not HEAD). Not .git/index:
    // git rewrites it on `git status` (and on the `git describe --dirty` below), which made every build after
    // one rebuild the crate.
    for path in git_paths() {
        println!("cargo:rerun-if-changed={path}");
    }
    // An edited source makes the build dirty: without these, `--dirty` was computed only when HEAD or the index
    // changed, and a run from an edited tree recorded the clean parent commit.
    for path in SOURCES {
        println!("cargo:rerun-if-changed={path}");
    }
    let commit = git(&["describe", "--always", "--dirty", "--abbrev=12"])
        .map(|o| String::from_utf8_lossy(&o).trim().to_string())
        .unwrap_or_default();
    let hash = if commit.ends_with("-dirty") {
        source_diff_hash().unwrap_or_default()
    } else {
        String::new()
    };
    println!("cargo:rustc-env=LODBENCH_GIT_COMMIT={commit}");
    println!("cargo:rustc-env=LODBENCH_SOURCE_DIFF_HASH={hash}");
}

/// The files of the git directory that say which commit is checked out: HEAD, the branch it names and the
/// packed refs, those that exist (cargo reruns a build script on every build while a watched file is missing;
/// none outside a checkout).
fn git_paths() -> Vec<String> {
    let text = |args: &[&str]| git(args).map(|o| String::from_utf8_lossy(&o).trim().to_string());
    let mut names = vec!["HEAD".to_string(), "packed-refs".to_string()];
    names.extend(text(&["symbolic-ref", "-q", "HEAD"]));
    names
        .iter()
        .filter_map(|n| text(&["rev-parse", "--git-path", n]))
        .filter(|p| std::path::Path::new(p).exists())
        .collect()
}

/// `git ARGS`'s stdout, None when git fails (no git, not a checkout).
fn git(args: &[&str]) -> Option<Vec<u8>> {
    Command::new("git")
        .args(args)
        .output()
        .ok()
        .filter(|o| o.status.success())
        .map(|o| o.stdout)
}

/// FNV-1a 64 (a fixed function, unlike std's hasher) over the uncommitted changes to [`SOURCES`] against HEAD
/// (`git diff HEAD --binary`, in a fixed format) and the names and contents of their untracked files, as 16
/// hex digits: two trees with the same commit and the same hash build the same binary.
fn source_diff_hash() -> Option<String> {
    let mut diff_args = vec![
        "-c",
        "core.quotepath=off",
        "diff",
        "HEAD",
        "--binary",
        "--no-ext-diff",
        "--no-textconv",
        "--no-color",
        "--src-prefix=a/",
        "--dst-prefix=b/",
        "--",
    ];
    diff_args.extend(SOURCES);
    let mut bytes = git(&diff_args)?;
    let mut untracked_args = vec!["ls-files", "--others", "--exclude-standard", "-z", "--"];
    untracked_args.extend(SOURCES);
    let untracked = git(&untracked_args)?;
    let mut names: Vec<&[u8]> = untracked
        .split(|&b| b == 0)
        .filter(|n| !n.is_empty())
        .collect();
    names.sort_unstable();
    for name in names {
        bytes.extend_from_slice(name);
        bytes.push(0);
        let path = String::from_utf8_lossy(name).to_string();
        bytes.extend(std::fs::read(&path).unwrap_or_default());
        bytes.push(0);
    }
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for b in bytes {
        h ^= u64::from(b);
        h = h.wrapping_mul(0x0100_0000_01b3);
    }
    Some(format!("{h:016x}"))
}
