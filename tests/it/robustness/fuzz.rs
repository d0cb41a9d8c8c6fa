//! Fuzzing in the test command: mutated example inputs
//! through every parser and entry point, with zero panics, zero hangs (a
//! time bound per case) and zero aborts allowed.
//!
//! - **Machine YAML, in process**: byte-level mutations of every example
//!   machine (flips, deletions, duplications, a dictionary of hostile
//!   tokens: `.nan`, `1e308`, anchors, brackets, deep indentation, …) through
//!   `load_bytes`, and every mutant that loads through `derive`, `compile`
//!   and one evaluation.
//! - **Settings, in process**: the same mutations of the motion settings.
//! - **The macro's inline tokens, in process**: text mutations of an inline
//!   machine through `chain_core::expand` (no compiler: it must return
//!   tokens, a `compile_error!` for bad input, never panic).
//! - **Every subcommand, spawned**: each input file of each subcommand's
//!   example invocation (machines, values with their CSV tables, settings,
//!   measurement, candidate, positioning, path, pose and swing CSVs) mutated
//!   in a scratch copy of its directory, then the command line itself
//!   (options dropped, duplicated, their values replaced by hostile ones).
//!   Exit status 0, 1 or 2 (a refused command line) only (a panic is 101,
//!   an abort a signal), no
//!   `panicked` on stderr, and within the time bound.
//!
//! The cases are deterministic (seeded); `CHAIN_FUZZ_CASES` scales their
//! number (the default runs in seconds; docs/robustness.md, "Fuzzing", has
//! the longer run and its findings). A failing case is written to the
//! scratch directory and named in the message.

use std::io::Read;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use crate::common::cli::scratch;
use crate::common::Rng;

const ROOT: &str = env!("CARGO_MANIFEST_DIR");

/// Cases per input, scaled by `CHAIN_FUZZ_CASES` (default `default`).
pub(crate) fn cases(default: usize) -> usize {
    std::env::var("CHAIN_FUZZ_CASES")
        .ok()
        .and_then(|v| v.parse::<usize>().ok())
        .map_or(default, |n| n.max(1))
}

/// Tokens that have broken parsers: numbers at and beyond the limits,
/// YAML's special values, anchors and aliases, structure characters,
/// expressions, units and very long runs.
const DICTIONARY: &[&str] = &[
    ".nan",
    ".inf",
    "-.inf",
    "1e308",
    "1e309",
    "-1e308",
    "1e-320",
    "0",
    "-0",
    "1e300",
    "9999999999999999999999",
    "nan",
    "inf",
    "null",
    "~",
    "&a ",
    "*a",
    "!!str ",
    "<<: *a",
    "{",
    "}",
    "[",
    "]",
    ":",
    ": ",
    ",",
    "-",
    "- ",
    "#",
    "'",
    "\"",
    "\\",
    "\t",
    "\n",
    "\r\n",
    "\n  ",
    "\n      ",
    "deg",
    "90deg",
    "pi",
    "1/0",
    "0/0",
    "x^64",
    "((((",
    "))))",
    "sin(",
    "\u{feff}",
    "\u{0}",
    "é",
    "1,2",
    ";",
    "+x",
    "-z",
    "prismatic",
    "rotary",
    "legendre",
];

/// One random mutation of `bytes`.
fn mutate(rng: &mut Rng, bytes: &[u8]) -> Vec<u8> {
    let mut out = bytes.to_vec();
    let rounds = 1 + (rng.next_u64() % 4) as usize;
    for _ in 0..rounds {
        let len = out.len().max(1);
        let at = (rng.next_u64() as usize) % len;
        match rng.next_u64() % 8 {
            // Flip a byte.
            0 if !out.is_empty() => {
                let k = at.min(out.len() - 1);
                out[k] ^= 1 << (rng.next_u64() % 8);
            }
            // Delete a range.
            1 if !out.is_empty() => {
                let end = (at + 1 + (rng.next_u64() % 40) as usize).min(out.len());
                out.drain(at.min(out.len())..end);
            }
            // Duplicate a range (a line or a block repeated).
            2 if !out.is_empty() => {
                let end = (at + 1 + (rng.next_u64() % 200) as usize).min(out.len());
                let piece: Vec<u8> = out[at.min(out.len())..end].to_vec();
                let times = 1 + (rng.next_u64() % 3) as usize;
                for _ in 0..times {
                    out.splice(at..at, piece.iter().copied());
                }
            }
            // Truncate.
            3 => out.truncate(at),
            // Replace a number-like run with a hostile token.
            4 => {
                let token = DICTIONARY[(rng.next_u64() as usize) % DICTIONARY.len()].as_bytes();
                let start = at.min(out.len());
                let end = out[start..]
                    .iter()
                    .position(|b| !(b.is_ascii_alphanumeric() || *b == b'.' || *b == b'-'))
                    .map_or(out.len(), |k| start + k);
                out.splice(start..end, token.iter().copied());
            }
            // Insert a token.
            _ => {
                let token = DICTIONARY[(rng.next_u64() as usize) % DICTIONARY.len()].as_bytes();
                let at = at.min(out.len());
                out.splice(at..at, token.iter().copied());
            }
        }
    }
    out
}

/// Runs `case` on a thread of its own, failing the test (with the input
/// saved under `name` in `dir`) when it panics or takes more than `bound`.
pub(crate) fn bounded(
    dir: &Path,
    name: &str,
    input: &[u8],
    bound: Duration,
    case: impl FnOnce() + Send + 'static,
) {
    let (tx, rx) = std::sync::mpsc::channel();
    let worker = std::thread::spawn(move || {
        let result = std::panic::catch_unwind(std::panic::AssertUnwindSafe(case));
        let _ = tx.send(result.is_ok());
    });
    match rx.recv_timeout(bound) {
        Ok(true) => {
            let _ = worker.join();
        }
        Ok(false) => {
            let saved = save(dir, name, input);
            panic!("{name} panicked; input saved as {}", saved.display());
        }
        Err(_) => {
            let saved = save(dir, name, input);
            panic!(
                "{name} took more than {bound:?}; input saved as {}",
                saved.display()
            );
        }
    }
}

fn save(dir: &Path, name: &str, input: &[u8]) -> PathBuf {
    let path = dir.join(format!("failing-{}", name.replace('/', "_")));
    std::fs::write(&path, input).expect("save the failing input");
    path
}

/// The example files of `dir` whose text contains `marker`.
fn examples(dir: &str, extension: &str, marker: &str) -> Vec<PathBuf> {
    let mut out: Vec<PathBuf> = std::fs::read_dir(Path::new(ROOT).join("examples").join(dir))
        .expect("examples dir")
        .map(|e| e.expect("entry").path())
        .filter(|p| p.extension().is_some_and(|e| e == extension))
        .filter(|p| std::fs::read_to_string(p).is_ok_and(|t| t.contains(marker)))
        .collect();
    out.sort();
    out
}

/// Mutated machine files through the loader, and each that loads through
/// the derivation, the tape and one evaluation.
#[test]
fn mutated_machine_files_never_panic_or_hang() {
    let dir = scratch("machines");
    let mut files = examples("machines", "yaml", "\nbodies:");
    files.extend(examples("robots", "yaml", "\nbodies:"));
    let mut rng = Rng::new(36);
    let (mut loaded, mut total) = (0usize, 0usize);
    for file in &files {
        let text = std::fs::read(file).expect("example");
        for k in 0..cases(40) {
            let input = mutate(&mut rng, &text);
            let name = format!("{}-{k}", file.file_name().unwrap().to_string_lossy());
            let copy = input.clone();
            let (tx, rx) = std::sync::mpsc::channel();
            bounded(&dir, &name, &input, Duration::from_secs(20), move || {
                let ok = match chain::core::load_bytes(&copy, "fuzz.yaml") {
                    Ok(m) => {
                        let model = chain::core::compile(&m);
                        let q = vec![0.1; chain::core::ErrorModel::variables(&model).len()];
                        let p: Vec<f64> = m
                            .parameters
                            .iter()
                            .map(|p| p.value.unwrap_or(1.0))
                            .collect();
                        let mut s = vec![0.0; 6 * chain::core::ErrorModel::errors(&model).len()];
                        chain::core::ErrorModel::sensitivity(&model, &q, &p, &mut s);
                        true
                    }
                    Err(d) => {
                        // The diagnostics render (the CLI's path).
                        let _ = d.to_string();
                        false
                    }
                };
                let _ = tx.send(ok);
            });
            total += 1;
            loaded += usize::from(rx.recv().unwrap_or(false));
        }
    }
    // The mutations reach past the loader as well as into it.
    assert!(
        loaded > 0 && loaded < total,
        "{loaded} of {total} mutants loaded"
    );
}

/// Mutated motion settings through their loader.
#[test]
fn mutated_settings_never_panic_or_hang() {
    let dir = scratch("settings");
    let base = Path::new(ROOT).join("examples/settings");
    let text = std::fs::read(base.join("seed002_concave.yaml")).expect("settings");
    let mut rng = Rng::new(37);
    for k in 0..cases(200) {
        let input = mutate(&mut rng, &text);
        let copy = input.clone();
        let base = base.clone();
        bounded(
            &dir,
            &format!("settings-{k}"),
            &input,
            Duration::from_secs(10),
            move || {
                let text = String::from_utf8_lossy(&copy);
                let _ = chain::core::settings::load_settings_str(&text, "fuzz.yaml", &base)
                    .map_err(|e| e.to_string());
            },
        );
    }
}

/// An inline machine, mutated as text, through the macro's expansion.
#[test]
fn mutated_inline_machines_never_panic_or_hang() {
    let dir = scratch("inline");
    let text = "pub Fuzz { machine: fuzz, parameters { L: 100 }, bodies { bed {}, \
        x_slide { parent: bed, joint: { type: prismatic, axis: +x, variable: x }, \
        errors: { dx: dxx, dy: [dyx, { name: EYX, powers: [1, 2] }], ez: ezx }, squareness: { ez: Sxy } }, \
        c_table { parent: bed, offset: [L/2, 0, 0], rotation: [{ about: z, angle: 90deg }], \
        joint: { type: rotary, axis: -z, variable: C }, errors: iso, location_errors: { ex: EAC } }, \
        arm { parent: x_slide, dh: { theta: 0.3, d: L, a: 25, alpha: -90deg, joint: rotary, variable: q, \
        errors: { theta: DT, beta: B } } } }, \
        workpiece: c_table, tool: arm, tool_point: [0, 0, -L], \
        statistics { dxx: { std: 0.01 } }, reliability { tolerance: { px: 0.03 }, grid: { x: [0, 1], C: [0], q: [0] } } }";
    let base: proc_macro2::TokenStream = text.parse().expect("the base parses");
    assert!(!chain::core::expand::expand(base)
        .to_string()
        .contains("compile_error"));
    let mut rng = Rng::new(38);
    let mut parsed = 0;
    for k in 0..cases(300) {
        let input = mutate(&mut rng, text.as_bytes());
        let Ok(source) = String::from_utf8(input.clone()) else {
            continue;
        };
        // What the compiler would hand the macro: only text that lexes
        // (parsed again on the case's thread: token streams stay on theirs).
        if source.parse::<proc_macro2::TokenStream>().is_err() {
            continue;
        }
        parsed += 1;
        bounded(
            &dir,
            &format!("inline-{k}"),
            &input,
            Duration::from_secs(20),
            move || {
                if let Ok(tokens) = source.parse::<proc_macro2::TokenStream>() {
                    let _ = chain::core::expand::expand(tokens).to_string();
                }
            },
        );
    }
    assert!(parsed > 0);
}

/// Each subcommand's example invocation: `(arguments, indices of the
/// arguments that are input files)`.
fn invocations() -> Vec<(Vec<String>, Vec<usize>)> {
    let e = |f: &str| format!("{ROOT}/examples/{f}");
    let v = |a: &[&str]| a.iter().map(|x| x.to_string()).collect::<Vec<_>>();
    vec![
        (
            v(&[
                "derive",
                &e("machines/ac_trunnion.yaml"),
                "--format",
                "json",
            ]),
            vec![1],
        ),
        (
            v(&[
                "reliability",
                &e("machines/gantry_grinder.yaml"),
                "--method",
                "form",
            ]),
            vec![1],
        ),
        (
            v(&[
                "sensitivity",
                &e("machines/gantry_grinder.yaml"),
                "--kind",
                "geometric",
            ]),
            vec![1],
        ),
        (
            v(&[
                "sobol",
                &e("machines/gantry_grinder.yaml"),
                "--at",
                "x=500,y=1500,z=600",
                "--samples",
                "500",
            ]),
            vec![1],
        ),
        (
            v(&["allocate", &e("machines/gantry_grinder.yaml")]),
            vec![1],
        ),
        (
            v(&[
                "compensate",
                &e("data/swing_htm50200.csv"),
                "--length",
                "577.11",
            ]),
            vec![1],
        ),
        (
            v(&[
                "inverse",
                &e("machines/cnc5_bevel.yaml"),
                "--pose",
                &e("paths/cnc5_bevel_pose.csv"),
            ]),
            vec![1, 3],
        ),
        (
            v(&[
                "path",
                &e("machines/gantry_grinder.yaml"),
                "--axes",
                &e("paths/gantry_path.csv"),
            ]),
            vec![1, 3],
        ),
        (
            v(&[
                "map",
                &e("machines/vmc3.yaml"),
                "--values",
                &e("values/vmc3.yaml"),
            ]),
            vec![1, 3],
        ),
        (
            v(&[
                "identify",
                &e("measurements/vmc3_probe.yaml"),
                "--measurements",
                &e("measurements/ballplate.csv"),
            ]),
            vec![1, 3],
        ),
        (
            v(&[
                "identify",
                &e("robots/puma560_dh.yaml"),
                "--measurements",
                &e("robots/puma560_tracker.csv"),
                "--validate",
                &e("robots/puma560_validate.csv"),
            ]),
            vec![1, 3, 5],
        ),
        (
            v(&[
                "plan",
                &e("measurements/vmc3_probe.yaml"),
                "--candidates",
                &e("measurements/candidates.csv"),
                "--count",
                "20",
            ]),
            vec![1, 3],
        ),
        (
            v(&[
                "export",
                &e("machines/vmc3.yaml"),
                "--values",
                &e("values/vmc3.yaml"),
                "--controller",
                "grid",
            ]),
            vec![1, 3],
        ),
        (
            v(&["positioning", &e("positioning/x_axis_runs.csv")]),
            vec![1],
        ),
        (
            v(&[
                "motion",
                &e("machines/cnc5_bevel.yaml"),
                "--settings",
                &e("settings/seed002_concave.yaml"),
                "--samples",
                "5",
            ]),
            vec![1, 3],
        ),
    ]
}

/// Runs the binary with `args` in `dir`; `Err` with what went wrong when it
/// panicked, died of a signal, exited with another status than 0, 1 or 2
/// (clap's usage error), or took longer than `bound` (then killed).
fn run_bounded(args: &[String], dir: &Path, bound: Duration) -> Result<i32, String> {
    let mut child = Command::new(env!("CARGO_BIN_EXE_chain"))
        .args(args)
        .current_dir(dir)
        .env("NO_COLOR", "1")
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .expect("run chain");
    let mut stderr = child.stderr.take().expect("stderr");
    let reader = std::thread::spawn(move || {
        let mut text = String::new();
        let _ = stderr.read_to_string(&mut text);
        text
    });
    let start = Instant::now();
    let status = loop {
        if let Some(status) = child.try_wait().expect("wait") {
            break status;
        }
        if start.elapsed() > bound {
            let _ = child.kill();
            let _ = child.wait();
            return Err(format!("took more than {bound:?}"));
        }
        std::thread::sleep(Duration::from_millis(5));
    };
    let text = reader.join().unwrap_or_default();
    match status.code() {
        // 2: a command line clap refuses (usage).
        Some(code @ 0..=2) if !text.contains("panicked") => Ok(code),
        Some(code) => Err(format!(
            "exit status {code}: {}",
            text.lines().take(5).collect::<Vec<_>>().join(" | ")
        )),
        None => Err(format!(
            "killed by a signal: {}",
            text.lines().take(5).collect::<Vec<_>>().join(" | ")
        )),
    }
}

/// Each subcommand with each of its input files mutated (in a scratch copy
/// of the file's directory, so that relative references such as a values
/// file's tables still resolve).
#[test]
fn every_subcommand_survives_mutated_input_files() {
    let mut rng = Rng::new(39);
    let work = scratch("inputs");
    let mut failures = Vec::new();
    let mut status = [0usize; 3];
    for (n, (args, files)) in invocations().into_iter().enumerate() {
        for &i in &files {
            let original = PathBuf::from(&args[i]);
            let source_dir = original.parent().expect("a directory");
            let copy_dir = work.join(format!("{n}-{i}"));
            std::fs::create_dir_all(&copy_dir).expect("scratch");
            for entry in std::fs::read_dir(source_dir).expect("dir") {
                let path = entry.expect("entry").path();
                if path.is_file() {
                    std::fs::copy(&path, copy_dir.join(path.file_name().unwrap())).expect("copy");
                }
            }
            let target = copy_dir.join(original.file_name().unwrap());
            let text = std::fs::read(&original).expect("input");
            for k in 0..cases(6) {
                let input = mutate(&mut rng, &text);
                std::fs::write(&target, &input).expect("write the mutant");
                let mut case = args.clone();
                case[i] = target.to_string_lossy().into_owned();
                let outcome = run_bounded(&case, &copy_dir, Duration::from_secs(60));
                if let Ok(code) = outcome {
                    status[code as usize] += 1;
                }
                if let Err(what) = outcome {
                    let saved = save(
                        &work,
                        &format!(
                            "{n}-{i}-{k}-{}",
                            original.file_name().unwrap().to_string_lossy()
                        ),
                        &input,
                    );
                    failures.push(format!(
                        "chain {} ({}): {what}",
                        case.join(" "),
                        saved.display()
                    ));
                }
            }
            // Restore the original for the next input of the command.
            std::fs::copy(&original, &target).expect("restore");
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
    // Mutants both refused and run to the end (exit 0 / exit 1).
    eprintln!(
        "mutated input files: {} ran, {} refused",
        status[0], status[1]
    );
    assert!(status[0] > 0 && status[1] > 0, "{status:?}");
}

/// Each subcommand's command line mutated: an option dropped or repeated,
/// an option's value (or a file argument) replaced by a hostile one.
#[test]
fn every_subcommand_survives_mutated_command_lines() {
    const VALUES: &[&str] = &[
        "",
        "-1",
        "0",
        "1e308",
        "nan",
        "inf",
        "-inf",
        "1e-320",
        "18446744073709551616",
        "x=",
        "=",
        "x=1e308",
        "x=nan,y=0",
        ",,,",
        "/dev/null",
        "/nonexistent",
        ".",
        "--",
        "-",
        "é",
        "\u{0}x",
        "1,2,3",
        "a=b=c",
        "deg",
    ];
    let mut rng = Rng::new(40);
    let work = scratch("argv");
    let mut failures = Vec::new();
    let mut status = [0usize; 3];
    for (args, _) in invocations() {
        for _ in 0..cases(8) {
            let mut case = args.clone();
            let at = 1 + (rng.next_u64() as usize) % (case.len() - 1).max(1);
            match rng.next_u64() % 3 {
                0 => {
                    case.remove(at.min(case.len() - 1).max(1));
                }
                1 => {
                    let item = case[at.min(case.len() - 1)].clone();
                    case.insert(at, item);
                }
                _ => {
                    let value = VALUES[(rng.next_u64() as usize) % VALUES.len()];
                    if !value.contains('\u{0}') {
                        let k = at.min(case.len() - 1);
                        case[k] = value.to_string();
                    }
                }
            }
            match run_bounded(&case, &work, Duration::from_secs(60)) {
                Ok(code) => status[code as usize] += 1,
                Err(what) => failures.push(format!("chain {}: {what}", case.join(" "))),
            }
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
    eprintln!("mutated command lines: {status:?} (exit 0, 1, 2)");
    assert!(status.iter().all(|&n| n > 0), "{status:?}");
}

/// The fuzzer's findings (docs/robustness.md, "Fuzzing"): records that hung
/// `identify` and `plan` (an SVD over infinities: a subnormal `std`, whose
/// weight overflows, and a pose value of 1e302, whose design squares do)
/// are refused at once, naming the file and line.
#[test]
fn overflowing_records_are_refused_not_solved() {
    let dir = scratch("findings");
    let e = |f: &str| format!("{ROOT}/examples/{f}");
    let edit = |file: &str, line: usize, from: &str, to: &str| -> String {
        let text = std::fs::read_to_string(e(file)).expect("example");
        let mut lines: Vec<String> = text.lines().map(str::to_string).collect();
        assert!(
            lines[line - 1].ends_with(from),
            "{file}:{line}: {}",
            lines[line - 1]
        );
        let keep = lines[line - 1].len() - from.len();
        lines[line - 1] = format!("{}{to}", &lines[line - 1][..keep]);
        let name = Path::new(file)
            .file_name()
            .unwrap()
            .to_string_lossy()
            .into_owned();
        let path = dir.join(format!("{line}-{name}"));
        std::fs::write(&path, lines.join("\n") + "\n").expect("write");
        path.to_string_lossy().into_owned()
    };
    let probe = e("measurements/vmc3_probe.yaml");
    let cases = [
        (
            vec!["identify".to_string(), probe.clone(), "--measurements".into(), edit("measurements/ballplate.csv", 270, ",0.001", ",0.001e-320")],
            "270-ballplate.csv: line 270: the model's sensitivity at this record's pose, divided by its std,",
        ),
        (
            vec!["identify".to_string(), probe.clone(), "--measurements".into(), edit("measurements/ballplate.csv", 224, "-220.0,0.003091,-0.003235,0.003866,0.001", "-220.1e300,0.003091,-0.003235,0.003866,0.001")],
            "224-ballplate.csv: line 224: the model's sensitivity",
        ),
        (
            vec!["plan".to_string(), probe, "--candidates".into(), edit("measurements/candidates.csv", 193, "-220.0", "-220.01e300"), "--count".into(), "20".into()],
            "193-candidates.csv: line 193: the model's sensitivity at this record's pose is not finite or beyond 1e100",
        ),
    ];
    for (args, message) in cases {
        assert_eq!(
            run_bounded(&args, &dir, Duration::from_secs(30)),
            Ok(1),
            "{args:?}"
        );
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        let stderr = crate::common::cli::unwrapped(&crate::common::cli::fails(&args));
        assert!(stderr.contains(message), "{stderr}");
    }
}
