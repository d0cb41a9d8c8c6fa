//! The library without the command line: a crate outside the workspace that
//! depends on `chain` with `default-features = false` and uses
//! `chain::machine!` and `reliability` pulls at most
//! [`MAX_DOWNSTREAM_CRATES`] crates (`cargo tree`), and compiles.
//!
//! The crate is written under `target/` with a copy of the workspace's
//! `Cargo.lock` (the same versions, so `--offline` resolves from the crates
//! the workspace build already fetched). `cargo check` builds it in its own
//! target directory there, kept between runs.

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};
use std::process::Command;

/// The bound on what a library user compiles (the crate itself
/// not counted).
const MAX_DOWNSTREAM_CRATES: usize = 40;

/// Crates that only the command line needs: none may reach the library.
const CLI_ONLY: [&str; 10] = [
    "clap",
    "indicatif",
    "plotters",
    "dejavu",
    "csv",
    "miette",
    "serde_json",
    "prettyplease",
    "rayon",
    "image",
];

fn cargo() -> Command {
    let mut c = Command::new(std::env::var("CARGO").unwrap_or_else(|_| "cargo".into()));
    // The child resolves and builds its own crate, not ours.
    for var in ["CARGO_TARGET_DIR", "CARGO_BUILD_TARGET_DIR", "RUSTFLAGS"] {
        c.env_remove(var);
    }
    c
}

/// Writes the downstream crate and returns its directory.
fn downstream_crate() -> PathBuf {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("downstream");
    std::fs::create_dir_all(dir.join("src")).unwrap();
    let manifest = format!(
        "[package]\nname = \"downstream\"\nversion = \"0.0.0\"\nedition = \"2021\"\npublish = false\n\n\
         [dependencies]\nchain = {{ path = {:?}, default-features = false }}\n\n\
         # Not part of any enclosing workspace.\n[workspace]\n",
        root.display().to_string()
    );
    let write = |name: &str, text: &[u8]| {
        let path = dir.join(name);
        // Leave unchanged files alone, so that cargo reuses its build.
        if std::fs::read(&path).ok().as_deref() != Some(text) {
            std::fs::write(&path, text).unwrap();
        }
    };
    write("Cargo.toml", manifest.as_bytes());
    // The trybuild pass case (a macro-generated model, inline and from a
    // file, and FORM on it) is the downstream crate's main.
    write(
        "src/main.rs",
        &std::fs::read(root.join("tests/ui/pass_downstream.rs")).unwrap(),
    );
    std::fs::create_dir_all(dir.join("examples/machines")).unwrap();
    write(
        "examples/machines/gantry_grinder.yaml",
        &std::fs::read(root.join("examples/machines/gantry_grinder.yaml")).unwrap(),
    );
    write(
        "Cargo.lock",
        &std::fs::read(root.join("Cargo.lock")).unwrap(),
    );
    dir
}

/// The crates of `cargo tree --prefix none` output, each once (`(*)` repeats
/// and proc-macro/host duplicates folded), without the root.
fn unique_crates(tree: &str) -> BTreeSet<String> {
    tree.lines()
        .skip(1)
        .map(|l| l.trim().trim_end_matches(" (*)").to_string())
        .filter(|l| !l.is_empty() && !l.starts_with('['))
        .filter(|l| !l.starts_with("downstream v"))
        .collect()
}

#[test]
fn library_alone_pulls_at_most_40_crates_and_compiles() {
    let dir = downstream_crate();
    let out = cargo()
        .args([
            "tree",
            "--offline",
            "-e",
            "normal,build",
            "--prefix",
            "none",
        ])
        .current_dir(&dir)
        .output()
        .expect("cargo runs");
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "cargo tree failed:\n{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let crates = unique_crates(&stdout);
    let names: BTreeSet<&str> = crates.iter().filter_map(|c| c.split(' ').next()).collect();
    for cli in CLI_ONLY {
        assert!(
            !names.contains(cli),
            "`{cli}` reaches the library:\n{stdout}"
        );
    }
    for needed in ["chain", "chain-core", "chain-macro", "reliability"] {
        assert!(names.contains(needed), "{needed} missing:\n{stdout}");
    }
    let list: Vec<&str> = crates.iter().map(String::as_str).collect();
    assert!(
        crates.len() <= MAX_DOWNSTREAM_CRATES,
        "{} crates (at most {MAX_DOWNSTREAM_CRATES}):\n{}",
        crates.len(),
        list.join("\n")
    );
    println!("{} crates:\n{}", crates.len(), list.join("\n"));

    let check = cargo()
        .args(["check", "--offline", "--quiet"])
        .current_dir(&dir)
        .env("CARGO_TARGET_DIR", dir.join("target"))
        .output()
        .expect("cargo runs");
    assert!(
        check.status.success(),
        "the downstream crate does not compile:\n{}",
        String::from_utf8_lossy(&check.stderr)
    );
}

#[test]
fn unique_crates_folds_repeats_and_skips_the_root() {
    let tree = "downstream v0.0.0 (/tmp/d)\nchain v0.1.0 (/w)\nserde v1.0.0\nserde v1.0.0 (*)\n\
                syn v3.0.0\nsyn v2.0.0\n[build-dependencies]\nautocfg v1.5.1\n";
    let got: Vec<String> = unique_crates(tree).into_iter().collect();
    assert_eq!(
        got,
        [
            "autocfg v1.5.1",
            "chain v0.1.0 (/w)",
            "serde v1.0.0",
            "syn v2.0.0",
            "syn v3.0.0"
        ]
    );
}

/// chain-core carries its built-in generator inside the crate (so that it
/// packages); it must stay the example file, byte for byte.
#[test]
fn built_in_generator_is_the_example_file() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let inside = std::fs::read(root.join("chain-core/src/input/cradle_generator.yaml")).unwrap();
    let example = std::fs::read(root.join("examples/machines/cradle_generator.yaml")).unwrap();
    assert!(
        inside == example,
        "chain-core/src/input/cradle_generator.yaml differs from examples/machines/cradle_generator.yaml"
    );
    assert_eq!(
        chain::core::settings::BUILTIN_GENERATOR.as_bytes(),
        example.as_slice()
    );
}
