//! Structure-aware fuzzing, beside the byte-level
//! mutations of `fuzz.rs`: proptest programs of *structural* edits of the
//! example inputs, so that the mutants get past the YAML and CSV syntax into
//! every rule behind it.
//!
//! - **YAML** (machines, motion settings, values files): each example is
//!   parsed into its tree (`chain_core::yaml::parse`) and edited: an entry
//!   deleted, duplicated (a repeated key) or renamed (to a key of the same
//!   kind of file, or a near miss), a node replaced by a subtree of another
//!   example or a hostile scalar, wrapped in a list or mapping, unwrapped,
//!   two values swapped, a node buried 70 levels deep. The tree is written
//!   back as YAML (block style for the top two levels, so that line numbers
//!   mean something) and read by its loader; a machine that loads is
//!   derived, compiled and evaluated once, settings that load are bound to
//!   their two machines.
//! - **CSV** (measurements, candidate poses, positioning runs, swing-angle
//!   records, a values table): header and rows edited (a column deleted,
//!   duplicated or renamed, a row dropped, repeated or made ragged, a cell
//!   replaced by a hostile one or another cell, comments and blank lines
//!   inserted) and read by their readers.
//!
//! The promise, for every case: no panic, within the time bound, and every
//! refusal located inside the text it refuses (a line from 1 to the last
//! line, an offset within the text). Each run of programs is tallied
//! ([`Tally`]): some mutants must be accepted and used, and the refusals
//! must fall on several lines, so that edits which only ever broke a
//! file's first line, or never got past the reader, fail the test.
//! Proptest shrinks a failing program to its smallest form; the programs
//! are seeded (`CHAIN_FUZZ_SEED` picks another sequence) and
//! `CHAIN_FUZZ_CASES` scales their number per input as for `fuzz.rs`
//! (docs/robustness.md, "Fuzzing").

use std::path::{Path, PathBuf};
use std::time::Duration;

use chain_core::diagnostic::Diagnostics;
use chain_core::yaml::{Node, NodeKind, ScalarStyle};
use proptest::prelude::*;
use proptest::test_runner::{Config, RngAlgorithm, TestCaseError, TestRng, TestRunner};

use crate::common::cli::scratch;
use crate::robustness::fuzz::{bounded, cases};

const ROOT: &str = env!("CARGO_MANIFEST_DIR");

/// A YAML tree as the edits see it.
#[derive(Debug, Clone, PartialEq)]
enum Y {
    /// A scalar and whether it was plain (unquoted).
    S(String, bool),
    /// A list.
    L(Vec<Y>),
    /// A mapping, in order (keys as scalars' text).
    M(Vec<(String, Y)>),
}

impl Y {
    fn of(n: &Node) -> Y {
        match &n.kind {
            NodeKind::Scalar(s) => Y::S(s.text.clone(), s.style == ScalarStyle::Plain),
            NodeKind::Sequence(items) => Y::L(items.iter().map(Y::of).collect()),
            NodeKind::Mapping(entries) => Y::M(
                entries
                    .iter()
                    .map(|(k, v)| (k.as_str().unwrap_or("").to_string(), Y::of(v)))
                    .collect(),
            ),
        }
    }

    /// The paths of every node, pre-order (the root is `[]`).
    fn paths(&self) -> Vec<Vec<usize>> {
        let mut out = vec![Vec::new()];
        let children: Vec<&Y> = match self {
            Y::S(..) => Vec::new(),
            Y::L(items) => items.iter().collect(),
            Y::M(entries) => entries.iter().map(|(_, v)| v).collect(),
        };
        for (i, c) in children.into_iter().enumerate() {
            out.extend(c.paths().into_iter().map(|mut p| {
                p.insert(0, i);
                p
            }));
        }
        out
    }

    fn at(&mut self, path: &[usize]) -> &mut Y {
        match path.split_first() {
            None => self,
            Some((&i, rest)) => match self {
                Y::L(items) => items[i].at(rest),
                Y::M(entries) => entries[i].1.at(rest),
                Y::S(..) => unreachable!("paths lead through containers"),
            },
        }
    }

    /// Every key, and every subtree (donors for replacements).
    fn collect(&self, keys: &mut Vec<String>, subtrees: &mut Vec<Y>) {
        subtrees.push(self.clone());
        match self {
            Y::S(..) => {}
            Y::L(items) => items.iter().for_each(|c| c.collect(keys, subtrees)),
            Y::M(entries) => entries.iter().for_each(|(k, v)| {
                keys.push(k.clone());
                v.collect(keys, subtrees);
            }),
        }
    }
}

/// A scalar as YAML writes it: plain when it was and reads back the same,
/// else double-quoted.
fn scalar(text: &str, plain: bool) -> String {
    let special = |c: char| "{}[],:#&*!|>'\"%@`".contains(c) || c.is_control();
    let safe = plain
        && !text.is_empty()
        && text.trim() == text
        && !text.contains(special)
        && !text.starts_with(['-', '?'])
        && text.len() < 200;
    if safe {
        return text.to_string();
    }
    let mut out = String::from("\"");
    for c in text.chars() {
        match c {
            '"' => out.push_str("\\\""),
            '\\' => out.push_str("\\\\"),
            '\n' => out.push_str("\\n"),
            '\t' => out.push_str("\\t"),
            c if c.is_control() => out.push_str(&format!("\\u{:04x}", c as u32)),
            c => out.push(c),
        }
    }
    out.push('"');
    out
}

/// Flow style (one line).
fn flow(y: &Y) -> String {
    match y {
        Y::S(t, plain) => scalar(t, *plain),
        Y::L(items) => format!(
            "[{}]",
            items.iter().map(flow).collect::<Vec<_>>().join(", ")
        ),
        Y::M(entries) => format!(
            "{{{}}}",
            entries
                .iter()
                .map(|(k, v)| format!("{}: {}", scalar(k, true), flow(v)))
                .collect::<Vec<_>>()
                .join(", ")
        ),
    }
}

/// The document: block style for the top two levels, flow below.
fn render(y: &Y) -> String {
    let mut out = String::new();
    match y {
        Y::M(entries) => {
            for (k, v) in entries {
                out.push_str(&scalar(k, true));
                match v {
                    Y::M(inner) if !inner.is_empty() => {
                        out.push_str(":\n");
                        for (k2, v2) in inner {
                            out.push_str(&format!("  {}: {}\n", scalar(k2, true), flow(v2)));
                        }
                    }
                    Y::L(items) if !items.is_empty() => {
                        out.push_str(":\n");
                        for item in items {
                            out.push_str(&format!("  - {}\n", flow(item)));
                        }
                    }
                    v => out.push_str(&format!(": {}\n", flow(v))),
                }
            }
        }
        other => {
            out.push_str(&flow(other));
            out.push('\n');
        }
    }
    out
}

/// Scalars that have broken loaders.
const HOSTILE: &[&str] = &[
    "1e308",
    "1e309",
    "-1e308",
    "1e-320",
    ".nan",
    ".inf",
    "-.inf",
    "nan",
    "0",
    "-0",
    "-1",
    "1/0",
    "0/0",
    "x^64",
    "((1)",
    "90deg",
    "1e3deg",
    "pi",
    "null",
    "~",
    "",
    "x",
    "+x",
    "-z",
    "rotary",
    "prismatic",
    "iso",
    "legendre",
    "normal",
    "é",
    "9999999999999999999999",
];

/// One structural edit: `op` picks the kind, `a` and `b` the nodes, keys
/// and donors (modulo their counts).
type Edit = (u8, u32, u32);

fn apply(doc: &mut Y, edit: Edit, keys: &[String], donors: &[Y]) {
    let (op, a, b) = edit;
    let paths = doc.paths();
    let path = &paths[a as usize % paths.len()];
    let containers: Vec<&Vec<usize>> = paths.iter().filter(|p| !p.is_empty()).collect();
    match op % 9 {
        // Delete an entry or item.
        0 if !containers.is_empty() => {
            let p = containers[a as usize % containers.len()];
            let (last, parent) = p.split_last().expect("not the root");
            match doc.at(parent) {
                Y::L(items) => {
                    items.remove(*last);
                }
                Y::M(entries) => {
                    entries.remove(*last);
                }
                Y::S(..) => {}
            }
        }
        // Duplicate an entry (the same key twice) or item.
        1 if !containers.is_empty() => {
            let p = containers[a as usize % containers.len()];
            let (last, parent) = p.split_last().expect("not the root");
            match doc.at(parent) {
                Y::L(items) => {
                    let copy = items[*last].clone();
                    items.insert(*last, copy);
                }
                Y::M(entries) => {
                    let copy = entries[*last].clone();
                    entries.insert(*last, copy);
                }
                Y::S(..) => {}
            }
        }
        // Rename a key: another key of the kind, or a near miss.
        2 if !containers.is_empty() => {
            let p = containers[a as usize % containers.len()];
            let (last, parent) = p.split_last().expect("not the root");
            if let Y::M(entries) = doc.at(parent) {
                let key = &mut entries[*last].0;
                *key = match b % 3 {
                    0 if !keys.is_empty() => keys[b as usize % keys.len()].clone(),
                    1 if key.len() > 1 => key[..key.len() - 1].to_string(),
                    _ => format!("{key}s"),
                };
            }
        }
        // Replace a node by a donor subtree.
        3 if !donors.is_empty() => *doc.at(path) = donors[b as usize % donors.len()].clone(),
        // Replace a node by a hostile scalar.
        4 => *doc.at(path) = Y::S(HOSTILE[b as usize % HOSTILE.len()].to_string(), b % 2 == 0),
        // Wrap a node in a list or a mapping.
        5 => {
            let node = doc.at(path).clone();
            *doc.at(path) = match b % 2 {
                0 => Y::L(vec![node]),
                _ => Y::M(vec![(
                    keys.get(b as usize % keys.len().max(1))
                        .cloned()
                        .unwrap_or_default(),
                    node,
                )]),
            };
        }
        // Unwrap a container into its first child.
        6 => {
            let node = doc.at(path);
            let first = match node {
                Y::L(items) => items.first().cloned(),
                Y::M(entries) => entries.first().map(|(_, v)| v.clone()),
                Y::S(..) => None,
            };
            if let Some(first) = first {
                *node = first;
            }
        }
        // Swap two values of a mapping.
        7 => {
            if let Y::M(entries) = doc.at(path) {
                if entries.len() >= 2 {
                    let i = b as usize % entries.len();
                    let j = (i + 1 + (b as usize / 7) % (entries.len() - 1)) % entries.len();
                    let (vi, vj) = (entries[i].1.clone(), entries[j].1.clone());
                    entries[i].1 = vj;
                    entries[j].1 = vi;
                }
            }
        }
        // Bury a node 70 levels deep (past the parser's depth limit).
        _ => {
            let mut node = doc.at(path).clone();
            for _ in 0..(b % 80) {
                node = Y::L(vec![node]);
            }
            *doc.at(path) = node;
        }
    }
}

/// A program of 1-5 edits.
fn program() -> impl Strategy<Value = Vec<Edit>> {
    prop::collection::vec((any::<u8>(), any::<u32>(), any::<u32>()), 1..6)
}

/// Every refusal lies within the text: a line from 1 to the last, an
/// offset within it (line 0 is a file-level refusal, none here).
fn located_inside(d: &Diagnostics, text: &str) -> Result<(), String> {
    let lines = text.lines().count().max(1);
    for e in d.iter() {
        let o = &e.origin;
        if o.line == 0 || o.line > lines + 1 || o.offset > text.len() {
            return Err(format!(
                "refusal outside the text ({} lines, {} bytes): line {}, offset {}: {}",
                lines,
                text.len(),
                o.line,
                o.offset,
                e.problem.headline()
            ));
        }
    }
    Ok(())
}

/// A runner of `programs` programs, seeded: the same programs every run
/// (`CHAIN_FUZZ_SEED`, a number, picks another sequence for longer runs).
fn runner(programs: usize) -> TestRunner {
    let seed: u64 = std::env::var("CHAIN_FUZZ_SEED")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(0);
    let mut bytes = [0u8; 32];
    bytes[..8].copy_from_slice(&seed.to_le_bytes());
    let config = Config {
        cases: programs as u32,
        failure_persistence: None,
        rng_algorithm: RngAlgorithm::ChaCha,
        ..Config::default()
    };
    TestRunner::new_with_rng(config, TestRng::from_seed(RngAlgorithm::ChaCha, &bytes))
}

/// What one case did with its input.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Outcome {
    /// Read (and, where the check goes further, used).
    Accepted,
    /// Refused; the first refusal's line when the reader locates it in the
    /// edited text.
    Refused(Option<usize>),
}

/// [`located_inside`], then the refusal's outcome.
fn refusal(d: &Diagnostics, text: &str) -> Result<Outcome, String> {
    let _ = d.to_string();
    located_inside(d, text)?;
    Ok(Outcome::Refused(d.iter().next().map(|e| e.origin.line)))
}

/// The outcomes of a run of programs.
#[derive(Debug, Default)]
struct Tally {
    accepted: usize,
    refused: usize,
    /// The distinct lines refusals were located at.
    lines: std::collections::BTreeSet<usize>,
}

impl Tally {
    fn add(&mut self, outcome: Outcome) {
        match outcome {
            Outcome::Accepted => self.accepted += 1,
            Outcome::Refused(line) => {
                self.refused += 1;
                self.lines.extend(line);
            }
        }
    }

    fn merge(&mut self, other: Tally) {
        self.accepted += other.accepted;
        self.refused += other.refused;
        self.lines.extend(other.lines);
    }

    /// The edits reached past the first refusal a reader makes: some
    /// inputs were accepted, some refused, and the refusals fell on at
    /// least `lines` different lines (a mutator that only ever broke the
    /// top of a file would give one).
    #[track_caller]
    fn assert_varied(&self, what: &str, lines: usize) {
        eprintln!(
            "{what}: {} accepted, {} refused at {} lines",
            self.accepted,
            self.refused,
            self.lines.len()
        );
        assert!(
            self.accepted > 0 && self.refused > 0 && self.lines.len() >= lines,
            "{what}: {self:?}"
        );
    }
}

/// One case: `check` on `text` within `bound` (a panic or a hang saved
/// under `dir`), its outcome added to `tally`, a failed check the case's
/// failure with its input.
fn run_case(
    dir: &Path,
    name: &str,
    text: String,
    bound: Duration,
    check: fn(String) -> Result<Outcome, String>,
    tally: &std::cell::RefCell<Tally>,
) -> Result<(), TestCaseError> {
    let (tx, rx) = std::sync::mpsc::channel();
    let input = text.clone();
    bounded(dir, name, text.as_bytes(), bound, move || {
        let _ = tx.send(check(input));
    });
    match rx.recv() {
        Ok(Ok(outcome)) => {
            tally.borrow_mut().add(outcome);
            Ok(())
        }
        Ok(Err(why)) => Err(TestCaseError::fail(format!("{why}\n--- input ---\n{text}"))),
        Err(_) => Err(TestCaseError::fail("the case sent nothing")),
    }
}

/// Runs `programs` programs of edits on `base` (with `keys` and `donors`
/// from every example of its kind) through `check`, each bounded in time.
fn run_programs(
    name: &str,
    base: &Y,
    keys: &[String],
    donors: &[Y],
    programs: usize,
    bound: Duration,
    check: fn(String) -> Result<Outcome, String>,
) -> Tally {
    let dir = scratch(name);
    let mut runner = runner(programs);
    let tally = std::cell::RefCell::new(Tally::default());
    let result = runner.run(&program(), |edits| {
        let mut doc = base.clone();
        for &e in &edits {
            apply(&mut doc, e, keys, donors);
        }
        run_case(&dir, name, render(&doc), bound, check, &tally)
    });
    if let Err(e) = result {
        panic!("{name}: {e}");
    }
    tally.into_inner()
}

fn yaml_files(dir: &str, marker: &str) -> Vec<PathBuf> {
    let mut out: Vec<PathBuf> = std::fs::read_dir(Path::new(ROOT).join("examples").join(dir))
        .expect("examples dir")
        .map(|e| e.expect("entry").path())
        .filter(|p| p.extension().is_some_and(|e| e == "yaml"))
        .filter(|p| std::fs::read_to_string(p).is_ok_and(|t| t.contains(marker)))
        .collect();
    out.sort();
    out
}

/// The example machines and robots.
fn machine_files() -> Vec<PathBuf> {
    let mut files = yaml_files("machines", "\nbodies:");
    files.extend(yaml_files("robots", "\nbodies:"));
    files
}

/// [`run_programs`] on every tree of a corpus, `check_of` giving each
/// tree's check; the outcomes over all of them.
fn run_corpus(
    prefix: &str,
    (trees, keys, donors): &(Vec<(String, Y)>, Vec<String>, Vec<Y>),
    programs: usize,
    bound: Duration,
    check_of: impl Fn(&str) -> fn(String) -> Result<Outcome, String>,
) -> Tally {
    let mut tally = Tally::default();
    for (name, t) in trees {
        tally.merge(run_programs(
            &format!("{prefix}-{name}"),
            t,
            keys,
            donors,
            programs,
            bound,
            check_of(name),
        ));
    }
    tally
}

fn tree(path: &Path) -> Y {
    let text = std::fs::read_to_string(path).expect("example");
    let parsed = chain_core::yaml::parse(&text);
    assert!(
        parsed.errors.is_empty(),
        "{}: {:?}",
        path.display(),
        parsed.errors
    );
    Y::of(parsed.root.as_ref().expect("a document"))
}

/// The trees of `files`, with the keys and subtrees of all of them.
fn corpus(files: &[PathBuf]) -> (Vec<(String, Y)>, Vec<String>, Vec<Y>) {
    let trees: Vec<(String, Y)> = files
        .iter()
        .map(|f| {
            (
                f.file_name().unwrap().to_string_lossy().into_owned(),
                tree(f),
            )
        })
        .collect();
    let (mut keys, mut donors) = (Vec::new(), Vec::new());
    for (_, t) in &trees {
        t.collect(&mut keys, &mut donors);
    }
    keys.sort();
    keys.dedup();
    // Small donors keep the mutants near their file's size.
    donors.retain(|d| flow(d).len() < 400);
    (trees, keys, donors)
}

/// The location check can fail: a refusal past the last line, or at line
/// 0, is caught.
#[test]
fn the_location_check_catches_a_refusal_outside_the_text() {
    use chain_core::diagnostic::Problem;
    let text = "a: 1\nb: 2\n";
    let at = |line: usize, offset: usize| {
        let origin = chain_core::model::Origin {
            offset,
            len: 0,
            line,
            column: 1,
            key: "a".into(),
        };
        Diagnostics::single("t.yaml", text, origin, Problem::NoRoot)
    };
    assert!(located_inside(&at(2, 5), text).is_ok());
    assert!(located_inside(&at(0, 0), text).is_err());
    assert!(located_inside(&at(9, 5), text).is_err());
    assert!(located_inside(&at(1, 99), text).is_err());
}

/// The rendering is faithful: every example, written back unedited, loads
/// as the original does (so that the edits, not the writer, make the
/// mutants).
#[test]
fn unedited_trees_load_as_their_files() {
    let files = machine_files();
    for f in &files {
        let original = chain_core::load_file(f).expect("example loads");
        let text = render(&tree(f));
        let again = chain_core::load_str(&text, &f.display().to_string())
            .unwrap_or_else(|d| panic!("{}: {d}\n{text}", f.display()));
        assert_eq!(again.errors.len(), original.errors.len(), "{}", f.display());
        assert_eq!(
            again.variables.len(),
            original.variables.len(),
            "{}",
            f.display()
        );
        assert_eq!(again.tool_point, original.tool_point, "{}", f.display());
    }
}

fn check_machine(text: String) -> Result<Outcome, String> {
    match chain_core::load_str(&text, "fuzz.yaml") {
        Ok(m) => {
            let model = chain_core::compile(&m);
            let q = vec![0.1; chain_core::ErrorModel::variables(&model).len()];
            let p: Vec<f64> = m
                .parameters
                .iter()
                .map(|p| p.value.unwrap_or(1.0))
                .collect();
            let mut s = vec![0.0; 6 * chain_core::ErrorModel::errors(&model).len()];
            chain_core::ErrorModel::sensitivity(&model, &q, &p, &mut s);
            Ok(Outcome::Accepted)
        }
        Err(d) => refusal(&d, &text),
    }
}

/// Structural edits of every example machine through the loader, and each
/// that loads through the derivation, the tape and one evaluation.
#[test]
fn edited_machine_trees_never_panic_and_are_refused_in_place() {
    run_corpus(
        "tree",
        &corpus(&machine_files()),
        cases(24),
        Duration::from_secs(20),
        |_| check_machine,
    )
    .assert_varied("edited machines", 20);
}

/// A scalar as the inline syntax writes it: its own tokens when they lex
/// and hold no top-level comma, else a string literal.
fn inline_scalar(text: &str, plain: bool) -> String {
    let lexes = || {
        text.parse::<proc_macro2::TokenStream>().is_ok_and(|t| {
            !t.is_empty()
                && t.into_iter()
                    .all(|tt| !matches!(&tt, proc_macro2::TokenTree::Punct(p) if p.as_char() == ',' || p.as_char() == ';'))
        })
    };
    if plain && !text.contains(['{', '}', '[', ']', '(', ')', '"', '\'']) && lexes() {
        text.to_string()
    } else {
        format!("{text:?}")
    }
}

/// The tree in the `machine!` inline syntax (docs of
/// `chain_core::inline`): `pub Fuzz { key: value, … }`.
fn inline(y: &Y) -> String {
    fn value(y: &Y) -> String {
        match y {
            Y::S(t, plain) => inline_scalar(t, *plain),
            Y::L(items) => format!(
                "[{}]",
                items.iter().map(value).collect::<Vec<_>>().join(", ")
            ),
            Y::M(entries) => format!("{{ {} }}", entries_of(entries)),
        }
    }
    fn entries_of(entries: &[(String, Y)]) -> String {
        entries
            .iter()
            .map(|(k, v)| format!("{}: {}", inline_scalar(k, true), value(v)))
            .collect::<Vec<_>>()
            .join(", ")
    }
    match y {
        Y::M(entries) => format!("pub Fuzz {{ {} }}", entries_of(entries)),
        other => format!("pub Fuzz {{ machine: {} }}", value(other)),
    }
}

/// Whether the macro's expansion of `source` is clean (no
/// `compile_error!`); `None` when the text does not lex (the compiler would
/// not hand it to the macro).
fn expand_clean(source: &str) -> Option<bool> {
    let tokens = source.parse::<proc_macro2::TokenStream>().ok()?;
    Some(
        !chain_core::expand::expand(tokens)
            .to_string()
            .contains("compile_error"),
    )
}

/// The example machines in the inline syntax: every one expands cleanly as
/// written, so the edits below reach the macro's rules, not only its
/// syntax.
#[test]
fn unedited_trees_expand_as_inline_machines() {
    let files = machine_files();
    let mut clean = Vec::new();
    for f in &files {
        if expand_clean(&inline(&tree(f))) == Some(true) {
            clean.push(f.file_name().unwrap().to_string_lossy().into_owned());
        }
    }
    eprintln!(
        "{} of {} example machines expand cleanly inline",
        clean.len(),
        files.len()
    );
    assert!(
        clean.iter().any(|f| f == "gantry_grinder.yaml"),
        "{clean:?}"
    );
    assert!(clean.len() == files.len(), "{clean:?} of {}", files.len());
}

/// The edited tree again, from its YAML (what the programs hand over), in
/// the inline syntax through the macro's expansion.
fn check_inline(text: String) -> Result<Outcome, String> {
    let parsed = chain_core::yaml::parse(&text);
    let Some(root) = parsed.root.as_ref() else {
        return Ok(Outcome::Refused(None));
    };
    Ok(match expand_clean(&inline(&Y::of(root))) {
        Some(true) => Outcome::Accepted,
        _ => Outcome::Refused(None),
    })
}

/// Structural edits of the example machines, written in the inline syntax,
/// through the macro's expansion (`chain_core::expand`, no compiler): a
/// `compile_error!` for what it refuses, never a panic, within the bound.
#[test]
fn edited_machine_trees_expand_inline_without_panic() {
    // The expansion's refusals are `compile_error!`s, located by the
    // compiler, so no lines are counted here.
    run_corpus(
        "inline",
        &corpus(&machine_files()),
        cases(8),
        Duration::from_secs(20),
        |_| check_inline,
    )
    .assert_varied("edited inline machines", 0);
}

fn check_settings(text: String) -> Result<Outcome, String> {
    let base = Path::new(ROOT).join("examples/settings");
    match chain_core::settings::load_settings_str(&text, "fuzz.yaml", &base) {
        Ok(s) => {
            // Bound to the machines they name (refusals located in the
            // settings or the machine files, never a panic).
            if let (Ok(g), Some(Ok(c))) = (s.load_generator(), s.load_cnc()) {
                let _ = s.bind(&g, &c, &[]).map_err(|d| d.to_string());
            }
            Ok(Outcome::Accepted)
        }
        Err(d) => refusal(&d, &text),
    }
}

/// Structural edits of the motion settings through their loader and, when
/// they load, the binding to their generator and CNC machine.
#[test]
fn edited_settings_trees_never_panic_and_are_refused_in_place() {
    run_corpus(
        "tree",
        &corpus(&yaml_files("settings", "roll:")),
        cases(60),
        Duration::from_secs(10),
        |_| check_settings,
    )
    .assert_varied("edited settings", 10);
}

fn values_machine(values: &str) -> &'static str {
    if values.starts_with("gantry") {
        "examples/machines/gantry_grinder.yaml"
    } else {
        "examples/machines/vmc3.yaml"
    }
}

/// An example machine, loaded once for every case that needs it.
fn example_machine(path: &'static str) -> &'static chain_core::model::Machine {
    type Loaded = Vec<(&'static str, &'static chain_core::model::Machine)>;
    static LOADED: std::sync::Mutex<Loaded> = std::sync::Mutex::new(Vec::new());
    let mut loaded = LOADED.lock().unwrap_or_else(|e| e.into_inner());
    if let Some((_, m)) = loaded.iter().find(|(p, _)| *p == path) {
        return m;
    }
    let m = chain_core::load_file(&Path::new(ROOT).join(path)).expect("example machine");
    let m: &'static chain_core::model::Machine = Box::leak(Box::new(m));
    loaded.push((path, m));
    m
}

fn check_values(file: &'static str, text: &str) -> Result<Outcome, String> {
    let machine = example_machine(values_machine(file));
    let base = Path::new(ROOT).join("examples/values");
    match chain_core::values::Values::parse(text, "fuzz.yaml", &base, machine) {
        Ok(_) => Ok(Outcome::Accepted),
        Err(chain_core::values::ValuesError::File(d)) => refusal(&d, text),
        // A table's refusals are located in the table's own file.
        Err(e) => {
            let _ = e.to_string();
            Ok(Outcome::Refused(None))
        }
    }
}

/// Structural edits of the values files (constants, coefficients, tables
/// with their CSV files beside them) through their reader.
#[test]
fn edited_values_trees_never_panic_and_are_refused_in_place() {
    run_corpus(
        "tree",
        &corpus(&yaml_files("values", "values")),
        cases(40),
        Duration::from_secs(10),
        |name| match name {
            "gantry_grinder.yaml" => |t| check_values("gantry_grinder.yaml", &t),
            _ => |t| check_values("vmc3.yaml", &t),
        },
    )
    .assert_varied("edited values files", 10);
}

// ---------------------------------------------------------------------------
// CSV tables.

/// A CSV table as the edits see it: comment lines kept in front.
#[derive(Debug, Clone)]
struct Table {
    comments: Vec<String>,
    header: Vec<String>,
    rows: Vec<Vec<String>>,
}

impl Table {
    /// The comments, header and the first `rows` rows of a CSV file.
    fn read(path: &Path, rows: usize) -> Table {
        let text = std::fs::read_to_string(path).expect("example CSV");
        let comments = text
            .lines()
            .take_while(|l| l.starts_with('#'))
            .map(String::from)
            .collect();
        let mut reader = csv::ReaderBuilder::new()
            .comment(Some(b'#'))
            .has_headers(false)
            .from_reader(text.as_bytes());
        let mut records = reader.records().map(|r| r.expect("example row"));
        let header = records
            .next()
            .expect("header")
            .iter()
            .map(String::from)
            .collect();
        let rows = records
            .take(rows)
            .map(|r| r.iter().map(String::from).collect())
            .collect();
        Table {
            comments,
            header,
            rows,
        }
    }

    fn render(&self, crlf: bool) -> String {
        let end = if crlf { "\r\n" } else { "\n" };
        let cell = |c: &String| {
            if c.contains([',', '"', '\n', '\r']) {
                format!("\"{}\"", c.replace('"', "\"\""))
            } else {
                c.clone()
            }
        };
        let mut out = String::new();
        for c in &self.comments {
            out.push_str(c);
            out.push_str(end);
        }
        for row in std::iter::once(&self.header).chain(&self.rows) {
            out.push_str(&row.iter().map(cell).collect::<Vec<_>>().join(","));
            out.push_str(end);
        }
        out
    }
}

/// Cells that have broken CSV readers.
const HOSTILE_CELLS: &[&str] = &[
    "",
    " ",
    "nan",
    "NaN",
    "inf",
    "-inf",
    "1e308",
    "1e309",
    "1e-320",
    "0",
    "-0",
    "9999999999999999999999",
    "abc",
    "1,5",
    "\"",
    "up",
    "down",
    "UP",
    "0.001e-320",
    "-220.1e300",
    "1/0",
    "#",
    "é",
    "\t1",
    "0x10",
];

fn edit_table(t: &mut Table, edit: Edit) {
    let (op, a, b) = edit;
    let (a, b) = (a as usize, b as usize);
    let width = t.header.len().max(1);
    match op % 10 {
        // Delete a column.
        0 if t.header.len() > 1 => {
            let c = a % t.header.len();
            t.header.remove(c);
            t.rows.iter_mut().filter(|r| r.len() > c).for_each(|r| {
                r.remove(c);
            });
        }
        // Duplicate a column (a header name twice).
        1 => {
            let c = a % width;
            if let Some(h) = t.header.get(c).cloned() {
                t.header.push(h);
                t.rows.iter_mut().for_each(|r| {
                    let v = r.get(c).cloned().unwrap_or_default();
                    r.push(v);
                });
            }
        }
        // Rename a column: another's name, a near miss, another case.
        2 if !t.header.is_empty() => {
            let c = a % t.header.len();
            let other = t.header[b % t.header.len()].clone();
            let h = &mut t.header[c];
            *h = match b % 3 {
                0 => other,
                1 => h.to_uppercase(),
                _ => format!("{h}_"),
            };
        }
        // Drop a row.
        3 if !t.rows.is_empty() => {
            t.rows.remove(a % t.rows.len());
        }
        // Repeat a row.
        4 if !t.rows.is_empty() => {
            let r = t.rows[a % t.rows.len()].clone();
            t.rows.insert(b % (t.rows.len() + 1), r);
        }
        // Make a row ragged.
        5 if !t.rows.is_empty() => {
            let n = t.rows.len();
            let row = &mut t.rows[a % n];
            if b % 2 == 0 {
                row.pop();
            } else {
                row.push("1".into());
            }
        }
        // A hostile cell.
        6 if !t.rows.is_empty() => {
            let n = t.rows.len();
            let row = &mut t.rows[a % n];
            if !row.is_empty() {
                let k = b % row.len();
                row[k] = HOSTILE_CELLS[(a / 7 + b) % HOSTILE_CELLS.len()].to_string();
            }
        }
        // Another cell of the table in its place.
        7 if !t.rows.is_empty() => {
            let n = t.rows.len();
            let donor = t.rows[b % n].get(a % width).cloned().unwrap_or_default();
            let row = &mut t.rows[a % n];
            if !row.is_empty() {
                let k = (a / 3) % row.len();
                row[k] = donor;
            }
        }
        // Only the header (or nothing at all).
        8 => {
            t.rows.clear();
            if b % 4 == 0 {
                t.header.clear();
            }
        }
        // A comment or a blank line among the rows.
        _ => {
            let at = b % (t.rows.len() + 1);
            let line = if a % 2 == 0 { "# a note" } else { "" };
            t.rows.insert(at, vec![line.to_string()]);
        }
    }
}

/// Runs programs of table edits through `check` (the rendered text).
fn run_table_programs(
    name: &str,
    base: &Table,
    programs: usize,
    check: fn(String) -> Result<Outcome, String>,
) -> Tally {
    let dir = scratch(name);
    let mut runner = runner(programs);
    let tally = std::cell::RefCell::new(Tally::default());
    let result = runner.run(&(program(), any::<bool>()), |(edits, crlf)| {
        let mut t = base.clone();
        for &e in &edits {
            edit_table(&mut t, e);
        }
        run_case(
            &dir,
            name,
            t.render(crlf),
            Duration::from_secs(20),
            check,
            &tally,
        )
    });
    if let Err(e) = result {
        panic!("{name}: {e}");
    }
    tally.into_inner()
}

/// An example table's first rows: a few are enough to reach every rule of
/// a table read row by row.
fn example_csv(path: &str) -> Table {
    Table::read(&Path::new(ROOT).join("examples").join(path), 12)
}

/// An example positioning run file, whole: the runs are checked as a
/// whole (every target in every run and direction), so a cut one is never
/// evaluated.
fn example_runs(path: &str) -> Table {
    Table::read(&Path::new(ROOT).join("examples").join(path), usize::MAX)
}

fn probe_machine() -> &'static chain_core::model::Machine {
    example_machine("examples/measurements/vmc3_probe.yaml")
}

fn check_measurements(
    text: String,
    layout: chain_core::measured::measurements::Layout,
) -> Result<Outcome, String> {
    use chain_core::measured::measurements::Measurements;
    match Measurements::parse(&text, "fuzz.csv", probe_machine(), &[], layout) {
        Ok(m) => {
            // The design of what was read (the exact sensitivity per row).
            let model = chain_core::compile(probe_machine());
            let _ =
                chain_core::measured::measurements::Design::new(&model, probe_machine(), &m.rows);
            Ok(Outcome::Accepted)
        }
        Err(e) => {
            let _ = e.to_string();
            refusal(e.diagnostics(), &text)
        }
    }
}

/// The tables' rendering is faithful: every example table, written back
/// unedited (LF or CRLF), is read as its file is.
#[test]
fn unedited_tables_are_read() {
    use chain_core::measured::measurements::Layout;
    use chain_core::measured::positioning::{AxisKind, Runs};
    for crlf in [false, true] {
        for (file, layout) in [
            ("measurements/ballplate.csv", Layout::Measurements),
            ("measurements/interferometer.csv", Layout::Measurements),
            ("measurements/candidates.csv", Layout::Candidates),
        ] {
            let text = example_csv(file).render(crlf);
            assert_eq!(
                check_measurements(text, layout),
                Ok(Outcome::Accepted),
                "{file}"
            );
        }
        for (file, kind) in [
            ("positioning/x_axis_runs.csv", AxisKind::Linear),
            ("positioning/c_axis_runs.csv", AxisKind::Rotary),
        ] {
            let text = example_runs(file).render(crlf);
            if let Err(e) = Runs::parse(&text, "fuzz.csv", kind) {
                panic!("{file}: {e}\n{text}");
            }
        }
    }
}

/// Structural edits of the measurement and candidate CSVs (a ball plate,
/// an interferometer, candidate poses) through their reader and design.
#[test]
fn edited_measurement_tables_never_panic_and_are_refused_in_place() {
    use chain_core::measured::measurements::Layout;
    for file in [
        "measurements/ballplate.csv",
        "measurements/interferometer.csv",
    ] {
        run_table_programs(
            &format!("table-{}", file.replace('/', "_")),
            &example_csv(file),
            cases(60),
            |t| check_measurements(t, Layout::Measurements),
        )
        .assert_varied(file, 5);
    }
    run_table_programs(
        "table-candidates",
        &example_csv("measurements/candidates.csv"),
        cases(60),
        |t| check_measurements(t, Layout::Candidates),
    )
    .assert_varied("candidates", 5);
}

/// Structural edits of positioning runs (linear and rotary), swing-angle
/// records and a values table through their readers.
#[test]
fn edited_run_swing_and_values_tables_never_panic_and_are_refused_in_place() {
    use chain_core::measured::positioning::{AxisKind, Runs};
    run_table_programs(
        "table-x-runs",
        &example_runs("positioning/x_axis_runs.csv"),
        // Most edits break a run file as a whole (a row missing, a run
        // repeated): more programs, so that some reach the evaluation.
        cases(240),
        |t| match Runs::parse(&t, "fuzz.csv", AxisKind::Linear) {
            Ok(runs) => {
                let _ = chain_core::measured::positioning::evaluate(&runs, Default::default());
                Ok(Outcome::Accepted)
            }
            Err(e) => refusal(e.diagnostics(), &t),
        },
    )
    .assert_varied("linear runs", 5);
    run_table_programs(
        "table-c-runs",
        &example_runs("positioning/c_axis_runs.csv"),
        cases(240),
        |t| match Runs::parse(&t, "fuzz.csv", AxisKind::Rotary) {
            Ok(_) => Ok(Outcome::Accepted),
            Err(e) => refusal(e.diagnostics(), &t),
        },
    )
    .assert_varied("rotary runs", 5);
    run_table_programs(
        "table-swing",
        &example_csv("data/swing_htm50200.csv"),
        cases(60),
        |t| {
            // Refusals name `file:line` in their message.
            match chain::compensate::records::parse_measurements("fuzz.csv", t.as_bytes()) {
                Ok(_) => Ok(Outcome::Accepted),
                Err(e) => {
                    let message = e.to_string();
                    let line = message
                        .strip_prefix("fuzz.csv:")
                        .and_then(|rest| rest.split(':').next())
                        .and_then(|n| n.parse().ok());
                    match message.starts_with("fuzz.csv:") {
                        true => Ok(Outcome::Refused(line)),
                        false => Err(format!("a refusal without its line: {message}")),
                    }
                }
            }
        },
    )
    .assert_varied("swing records", 5);
    run_table_programs(
        "table-values",
        &example_csv("values/x_axis.csv"),
        cases(60),
        |t| match chain_core::values::csv::CsvFile::parse_bytes(t.as_bytes(), "fuzz.csv", "help") {
            Ok(f) => {
                let _ = f.rows().count();
                Ok(Outcome::Accepted)
            }
            Err(d) => refusal(&d, &t),
        },
    )
    .assert_varied("values table", 5);
}
