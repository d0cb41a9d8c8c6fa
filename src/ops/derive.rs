//! `chain derive` as a request and a document (machine-format spec): the
//! exact first-order error model of a machine in the frame asked (the
//! file's by default). The CLI renders it as text, JSON, LaTeX or Rust;
//! Python's `Machine.derive` returns its JSON document.

use chain_core::export::{self, DeriveJson};
use chain_core::model::Frame;
use chain_core::{Machine, SymbolicModel};
use serde::{Serialize, Serializer};

/// The request of `chain derive`.
#[derive(Debug, Clone, Copy, Default)]
pub struct DeriveRequest {
    /// `--frame`: the frame of `p` and `o`; `None`: the file's `frame`.
    pub frame: Option<Frame>,
}

/// The document of `chain derive`: the symbolic model (JSON: the spec's
/// [`DeriveJson`]).
#[derive(Debug, Clone)]
pub struct Derivation {
    /// The derived model.
    pub model: SymbolicModel,
}

impl Derivation {
    /// The spec's JSON document.
    pub fn document(&self) -> DeriveJson {
        export::to_json(&self.model)
    }
}

impl Serialize for Derivation {
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        self.document().serialize(serializer)
    }
}

/// Derives the model of `machine` in the frame asked.
pub fn run(machine: &Machine, request: &DeriveRequest) -> Derivation {
    let frame = request.frame.unwrap_or(machine.frame);
    Derivation {
        model: chain_core::derive_in(machine, frame),
    }
}
