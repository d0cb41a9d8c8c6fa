//! The runtime evaluator: a [`SymbolicModel`] flattened into a tape that
//! evaluates the error vector, the full sensitivity matrix and the nominal
//! pose at a point without re-deriving anything.
//!
//! Registers hold `1`, then one slot per symbol (`x`, `cos A`, `sin A`, `L`,
//! ...), then one slot per distinct monomial; each monomial is the product of a
//! shorter monomial and one symbol, so shared sub-products are computed once.
//! Every output is a short dot product of coefficients with monomial registers.
//!
//! Every symbol a model uses gets a register: besides the ones loaded up front
//! (each prismatic variable, `cos`/`sin` of each rotary variable, each
//! parameter) a symbol first met in a monomial is loaded then. That is how the
//! value `A` of a rotary variable reaches the tape when a powers, Legendre or
//! Chebyshev function slot varies along a rotary axis (measured-machines spec,
//! section 1: the slot is a polynomial in the variable's value).

use std::collections::{HashMap, HashSet};
use std::sync::Mutex;

use crate::algebra::{Monomial, Poly, Symbol};
use crate::derive::SymbolicModel;
use crate::model::{JointKind, Machine};
use crate::model_trait::{ErrorModel, Pose};

/// Registers kept on the stack; larger tapes use a heap buffer per call.
const STACK_REGISTERS: usize = 256;

/// Points per block of [`CompiledModel::sensitivity_batch`].
pub const BATCH_LANES: usize = 8;

pub use crate::model_trait::BatchError;
use crate::model_trait::{error_rows, error_shape, sensitivity_shape};

/// The registers of one block: one lane per point.
type Lanes = [f64; BATCH_LANES];

thread_local! {
    /// Each thread's block registers, reused by every batch call on it (no
    /// allocation per call once they have grown to the largest tape).
    static BLOCK_REGISTERS: std::cell::RefCell<Vec<Lanes>> = const { std::cell::RefCell::new(Vec::new()) };
}

/// Runs `f` with this thread's block registers (a fresh buffer if they are
/// in use further up the stack).
fn with_block_registers<R>(f: impl FnOnce(&mut Vec<Lanes>) -> R) -> R {
    BLOCK_REGISTERS.with(|cell| match cell.try_borrow_mut() {
        Ok(mut regs) => f(&mut regs),
        Err(_) => f(&mut Vec::new()),
    })
}

/// A machine's error model compiled to a flat tape. Implements [`ErrorModel`].
#[derive(Debug, Clone)]
pub struct CompiledModel {
    variables: Vec<&'static str>,
    parameters: Vec<&'static str>,
    errors: Vec<&'static str>,
    parameter_values: Vec<Option<f64>>,
    /// Register index and meaning of each symbol slot but `cos`/`sin` of
    /// the rotary variables.
    loads: Vec<(usize, Symbol)>,
    /// `(cos register, sin register, variable)` of each rotary variable,
    /// both by [`crate::lanes::sin_cos`].
    trig: Vec<(usize, usize, usize)>,
    /// `regs[dst] = regs[a] * regs[b]`, in order.
    products: Vec<(u32, u32, u32)>,
    register_count: usize,
    /// Sensitivity outputs: `(row-major index c*N+j, terms range)`.
    sensitivity: Vec<(u32, u32, u32)>,
    /// The sensitivity outputs that vary with the point (a term on a
    /// register other than register 0, the constant `1`).
    varying: Vec<(u32, u32, u32)>,
    /// One point's sensitivity matrix with every constant entry (zeros and
    /// the outputs whose terms are all on register 0) in place: each matrix starts as
    /// a copy of it, then [`CompiledModel::varying`] is written.
    template: Vec<f64>,
    /// Nominal outputs: `(0..9 rotation row-major, 9..12 position, terms range)`.
    nominal: Vec<(u32, u32, u32)>,
    /// `(coefficient, register)` terms of all outputs.
    terms: Vec<(f64, u32)>,
}

/// Compiles a machine: derive, then flatten.
pub fn compile(machine: &Machine) -> CompiledModel {
    CompiledModel::new(&crate::derive(machine))
}

impl CompiledModel {
    /// Flattens a symbolic model.
    pub fn new(model: &SymbolicModel) -> CompiledModel {
        // Register 0 holds 1.0.
        let mut builder = TapeBuilder {
            registers: 1,
            ..TapeBuilder::default()
        };
        let mut trig = Vec::new();
        for (v, (_, kind)) in model.variables.iter().enumerate() {
            let i = crate::algebra::index_u16(v);
            match kind {
                JointKind::Prismatic => builder.load(Symbol::Var(i)),
                JointKind::Rotary => {
                    builder.load(Symbol::Cos(i));
                    builder.load(Symbol::Sin(i));
                    trig.push((builder.registers - 2, builder.registers - 1, v));
                }
            }
        }
        for k in 0..model.parameters.len() {
            builder.load(Symbol::Param(crate::algebra::index_u16(k)));
        }
        let n = model.errors.len();
        let mut sensitivity = Vec::new();
        for (c, entries) in model.components.iter().enumerate() {
            for (j, poly) in entries {
                let range = builder.poly(poly);
                sensitivity.push((to_u32(c * n + j), range.0, range.1));
            }
        }
        let mut nominal = Vec::new();
        for i in 0..3 {
            for j in 0..3 {
                let poly = &model.nominal_rotation[i][j];
                if !poly.is_zero() {
                    let range = builder.poly(poly);
                    nominal.push((to_u32(3 * i + j), range.0, range.1));
                }
            }
        }
        for i in 0..3 {
            let poly = &model.nominal_position[i];
            if !poly.is_zero() {
                let range = builder.poly(poly);
                nominal.push((to_u32(9 + i), range.0, range.1));
            }
        }
        let terms = builder.terms;
        let constant = |&(_, start, end): &(u32, u32, u32)| {
            terms[start as usize..end as usize].iter().all(|t| t.1 == 0)
        };
        let mut template = vec![0.0; 6 * n];
        for output in sensitivity.iter().filter(|o| constant(o)) {
            // The same sum as `dot` with register 0 (the constant 1).
            let (idx, start, end) = *output;
            template[idx as usize] = terms[start as usize..end as usize]
                .iter()
                .map(|&(c, _)| c * 1.0)
                .sum();
        }
        let varying = sensitivity
            .iter()
            .filter(|o| !constant(o))
            .copied()
            .collect();
        let loads = builder
            .loads
            .into_iter()
            .filter(|(_, s)| !matches!(s, Symbol::Cos(_) | Symbol::Sin(_)))
            .collect();
        CompiledModel {
            variables: model.variables.iter().map(|v| intern(&v.0)).collect(),
            parameters: model.parameters.iter().map(|p| intern(&p.0)).collect(),
            errors: model.errors.iter().map(|e| intern(e)).collect(),
            parameter_values: model.parameters.iter().map(|p| p.1).collect(),
            loads,
            trig,
            products: builder.products,
            register_count: builder.registers,
            sensitivity,
            varying,
            template,
            nominal,
            terms,
        }
    }

    /// The parameter values given in the machine file (`None`: symbolic).
    pub fn parameter_values(&self) -> &[Option<f64>] {
        &self.parameter_values
    }

    fn with_registers<R>(&self, q: &[f64], p: &[f64], f: impl FnOnce(&[f64]) -> R) -> R {
        let mut stack = [0.0f64; STACK_REGISTERS];
        let mut heap = Vec::new();
        let regs: &mut [f64] = if self.register_count <= STACK_REGISTERS {
            &mut stack[..self.register_count]
        } else {
            heap.resize(self.register_count, 0.0);
            &mut heap
        };
        regs[0] = 1.0;
        for &(r, s) in &self.loads {
            regs[r] = SymbolicModel::symbol_value(s, q, p);
        }
        for &(rc, rs, v) in &self.trig {
            let x = q.get(v).copied().unwrap_or(f64::NAN);
            (regs[rs], regs[rc]) = crate::lanes::sin_cos_one(x);
        }
        for &(dst, a, b) in &self.products {
            regs[dst as usize] = regs[a as usize] * regs[b as usize];
        }
        f(regs)
    }

    /// The sensitivity matrix at many points: `qs` holds the points one after
    /// another (`variables().len()` values each), `out` receives each point's
    /// row-major `6 × errors().len()` matrix in the same order. The tape runs
    /// over blocks of [`BATCH_LANES`] points per instruction (structure of
    /// arrays); the last block is padded with copies of its last point and only
    /// its real points are written. Blocks run in parallel under the
    /// `parallel` feature ([`ErrorModel::sensitivity_points`] runs them on the
    /// calling thread). Every value equals [`ErrorModel::sensitivity`] at
    /// that point (the same products and sums in the same order).
    ///
    /// # Errors
    /// [`BatchError`] when `qs` is not a whole number of points or `out` does
    /// not hold exactly one matrix per point.
    pub fn sensitivity_batch(
        &self,
        qs: &[f64],
        p: &[f64],
        out: &mut [f64],
    ) -> Result<(), BatchError> {
        let nv = self.variables.len();
        let (_, width) = sensitivity_shape(nv, self.errors.len(), qs.len(), out.len())?;
        if width == 0 {
            return Ok(());
        }
        let run = |(qb, ob): (&[f64], &mut [f64])| {
            with_block_registers(|regs| self.sensitivity_block(qb, p, ob, regs))
        };
        #[cfg(feature = "parallel")]
        {
            use rayon::prelude::*;
            qs.par_chunks(nv * BATCH_LANES)
                .zip(out.par_chunks_mut(width * BATCH_LANES))
                .for_each(run);
        }
        #[cfg(not(feature = "parallel"))]
        qs.chunks(nv * BATCH_LANES)
            .zip(out.chunks_mut(width * BATCH_LANES))
            .for_each(run);
        Ok(())
    }

    /// The errors `E = S · e` at many points through the batched tape:
    /// `qs` as in [`CompiledModel::sensitivity_batch`], `es` one row of
    /// `errors().len()` values per point or one row for every point, `out`
    /// six values per point. Blocks run in parallel under the `parallel`
    /// feature ([`ErrorModel::error_points`] runs them on the calling
    /// thread). Every value equals [`ErrorModel::error`] at that point, bit
    /// for bit (the same products and sums in the same order).
    ///
    /// # Errors
    /// [`BatchError`] when a slice does not fit the number of points.
    pub fn error_batch(
        &self,
        qs: &[f64],
        p: &[f64],
        es: &[f64],
        out: &mut [f64],
    ) -> Result<(), BatchError> {
        let nv = self.variables.len();
        let broadcast = error_shape(nv, self.errors.len(), qs.len(), es.len(), out.len())?;
        let n = self.errors.len();
        let run = |(b, (qb, ob)): (usize, (&[f64], &mut [f64]))| {
            let eb = error_rows(es, broadcast, n, b * BATCH_LANES, ob.len() / 6);
            with_block_registers(|regs| self.error_block(qb, p, eb, broadcast, ob, regs))
        };
        #[cfg(feature = "parallel")]
        {
            use rayon::prelude::*;
            qs.par_chunks(nv * BATCH_LANES)
                .zip(out.par_chunks_mut(6 * BATCH_LANES))
                .enumerate()
                .for_each(run);
        }
        #[cfg(not(feature = "parallel"))]
        qs.chunks(nv * BATCH_LANES)
            .zip(out.chunks_mut(6 * BATCH_LANES))
            .enumerate()
            .for_each(run);
        Ok(())
    }

    /// Loads and runs the tape over one block of at most [`BATCH_LANES`]
    /// points (`qs`, padded with its last point) into `regs`.
    fn run_block(&self, qs: &[f64], p: &[f64], regs: &mut Vec<Lanes>) {
        const W: usize = BATCH_LANES;
        const { assert!(W % crate::lanes::LANES == 0) };
        let nv = self.variables.len();
        let real = qs.len() / nv;
        regs.resize(self.register_count, [0.0; W]);
        regs[0] = [1.0; W];
        // Variable `i` of every lane's point.
        let variable = |i: usize| -> Lanes {
            std::array::from_fn(|lane| {
                let k = lane.min(real - 1);
                qs[k * nv..(k + 1) * nv].get(i).copied().unwrap_or(f64::NAN)
            })
        };
        for &(r, s) in &self.loads {
            regs[r] = match s {
                Symbol::Var(i) => variable(usize::from(i)),
                Symbol::Param(_) => [SymbolicModel::symbol_value(s, &[], p); BATCH_LANES],
                // Not among the loads: `trig` below.
                Symbol::Cos(_) | Symbol::Sin(_) => continue,
            };
        }
        for &(rc, rs, v) in &self.trig {
            for (h, x) in variable(v).chunks_exact(crate::lanes::LANES).enumerate() {
                let x = std::array::from_fn(|l| x[l]);
                let (sin, cos) = crate::lanes::sin_cos(x);
                let at = h * crate::lanes::LANES..(h + 1) * crate::lanes::LANES;
                regs[rs][at.clone()].copy_from_slice(&sin);
                regs[rc][at].copy_from_slice(&cos);
            }
        }
        for &(dst, a, b) in &self.products {
            let (x, y) = (regs[a as usize], regs[b as usize]);
            regs[dst as usize] = std::array::from_fn(|l| x[l] * y[l]);
        }
    }

    /// One output's dot product in every lane.
    #[inline]
    fn dot_lanes(&self, regs: &[Lanes], start: u32, end: u32) -> Lanes {
        let mut acc = [-0.0f64; BATCH_LANES];
        for &(c, r) in &self.terms[start as usize..end as usize] {
            let x = &regs[r as usize];
            for (a, x) in acc.iter_mut().zip(x) {
                *a += c * x;
            }
        }
        acc
    }

    /// One block's sensitivity matrices.
    fn sensitivity_block(&self, qs: &[f64], p: &[f64], out: &mut [f64], regs: &mut Vec<Lanes>) {
        let width = 6 * self.errors.len();
        self.run_block(qs, p, regs);
        // Each point's matrix starts as the template; then each varying
        // output is written into every real point's matrix.
        let mut rows = out.chunks_exact_mut(width);
        let mut rows: [&mut [f64]; BATCH_LANES] =
            std::array::from_fn(|_| rows.next().unwrap_or_default());
        // (The rows past a short last block are empty.)
        for row in rows.iter_mut().filter(|row| !row.is_empty()) {
            row.copy_from_slice(&self.template);
        }
        for &(idx, start, end) in &self.varying {
            let acc = self.dot_lanes(regs, start, end);
            for (row, v) in rows.iter_mut().zip(acc) {
                if let Some(o) = row.get_mut(idx as usize) {
                    *o = v;
                }
            }
        }
    }

    /// One block's errors: `es` one row per real point, or one row for all
    /// (`broadcast`); `out` six values per real point.
    fn error_block(
        &self,
        qs: &[f64],
        p: &[f64],
        es: &[f64],
        broadcast: bool,
        out: &mut [f64],
        regs: &mut Vec<Lanes>,
    ) {
        let n = self.errors.len();
        self.run_block(qs, p, regs);
        out.iter_mut().for_each(|v| *v = 0.0);
        for &(idx, start, end) in &self.sensitivity {
            let acc = self.dot_lanes(regs, start, end);
            let (c, j) = (idx as usize / n, idx as usize % n);
            for (l, (o, a)) in out.chunks_exact_mut(6).zip(acc).enumerate() {
                let e = if broadcast { j } else { l * n + j };
                o[c] += a * es.get(e).copied().unwrap_or(0.0);
            }
        }
    }

    #[inline]
    fn dot(&self, regs: &[f64], start: u32, end: u32) -> f64 {
        self.terms[start as usize..end as usize]
            .iter()
            .map(|&(c, r)| c * regs[r as usize])
            .sum()
    }
}

impl ErrorModel for CompiledModel {
    fn variables(&self) -> &[&str] {
        &self.variables
    }

    fn parameters(&self) -> &[&str] {
        &self.parameters
    }

    fn errors(&self) -> &[&str] {
        &self.errors
    }

    fn error(&self, q: &[f64], p: &[f64], e: &[f64], out: &mut [f64; 6]) {
        let n = self.errors.len();
        *out = [0.0; 6];
        self.with_registers(q, p, |regs| {
            for &(idx, start, end) in &self.sensitivity {
                let idx = idx as usize;
                let (c, j) = (idx / n, idx % n);
                out[c] += self.dot(regs, start, end) * e.get(j).copied().unwrap_or(0.0);
            }
        });
    }

    fn sensitivity(&self, q: &[f64], p: &[f64], out: &mut [f64]) {
        // The template, then zeros past it (an `out` longer than 6·N).
        let k = out.len().min(self.template.len());
        out[..k].copy_from_slice(&self.template[..k]);
        out[k..].fill(0.0);
        self.with_registers(q, p, |regs| {
            for &(idx, start, end) in &self.varying {
                if let Some(slot) = out.get_mut(idx as usize) {
                    *slot = self.dot(regs, start, end);
                }
            }
        });
    }

    fn sensitivity_points(&self, qs: &[f64], p: &[f64], out: &mut [f64]) -> Result<(), BatchError> {
        let nv = self.variables.len();
        let (_, width) = sensitivity_shape(nv, self.errors.len(), qs.len(), out.len())?;
        if width == 0 {
            return Ok(());
        }
        with_block_registers(|regs| {
            for (qb, ob) in qs
                .chunks(nv * BATCH_LANES)
                .zip(out.chunks_mut(width * BATCH_LANES))
            {
                self.sensitivity_block(qb, p, ob, regs);
            }
        });
        Ok(())
    }

    fn error_points(
        &self,
        qs: &[f64],
        p: &[f64],
        es: &[f64],
        out: &mut [f64],
    ) -> Result<(), BatchError> {
        let nv = self.variables.len();
        let broadcast = error_shape(nv, self.errors.len(), qs.len(), es.len(), out.len())?;
        let n = self.errors.len();
        with_block_registers(|regs| {
            for (b, (qb, ob)) in qs
                .chunks(nv * BATCH_LANES)
                .zip(out.chunks_mut(6 * BATCH_LANES))
                .enumerate()
            {
                let eb = error_rows(es, broadcast, n, b * BATCH_LANES, ob.len() / 6);
                self.error_block(qb, p, eb, broadcast, ob, regs);
            }
        });
        Ok(())
    }

    fn nominal(&self, q: &[f64], p: &[f64]) -> Pose {
        let mut flat = [0.0; 12];
        self.with_registers(q, p, |regs| {
            for &(idx, start, end) in &self.nominal {
                flat[idx as usize] = self.dot(regs, start, end);
            }
        });
        Pose {
            rotation: [
                [flat[0], flat[1], flat[2]],
                [flat[3], flat[4], flat[5]],
                [flat[6], flat[7], flat[8]],
            ],
            position: [flat[9], flat[10], flat[11]],
        }
    }
}

fn to_u32(i: usize) -> u32 {
    u32::try_from(i).unwrap_or(u32::MAX)
}

#[derive(Default)]
struct TapeBuilder {
    registers: usize,
    loads: Vec<(usize, Symbol)>,
    symbol_reg: HashMap<Symbol, u32>,
    monomial_reg: HashMap<Monomial, u32>,
    products: Vec<(u32, u32, u32)>,
    terms: Vec<(f64, u32)>,
}

impl TapeBuilder {
    fn load(&mut self, s: Symbol) {
        let r = self.registers;
        self.registers += 1;
        self.loads.push((r, s));
        self.symbol_reg.insert(s, to_u32(r));
        self.monomial_reg.insert(Monomial::symbol(s), to_u32(r));
    }

    /// The register of a symbol, loading it on first use.
    fn symbol(&mut self, s: Symbol) -> u32 {
        if let Some(&r) = self.symbol_reg.get(&s) {
            return r;
        }
        self.load(s);
        to_u32(self.registers - 1)
    }

    fn monomial(&mut self, m: &Monomial) -> u32 {
        if m.is_one() {
            return 0;
        }
        if let Some(&r) = self.monomial_reg.get(m) {
            return r;
        }
        // m = parent * last symbol
        let Some((parent, sym)) = m.split_last() else {
            return 0;
        };
        let a = self.monomial(&parent);
        let b = self.symbol(sym);
        if a == 0 {
            // A single symbol (first met here, or the caller asked for it).
            return b;
        }
        let dst = to_u32(self.registers);
        self.registers += 1;
        self.products.push((dst, a, b));
        self.monomial_reg.insert(m.clone(), dst);
        dst
    }

    fn poly(&mut self, p: &Poly) -> (u32, u32) {
        let start = to_u32(self.terms.len());
        for (m, c) in p.terms() {
            let r = self.monomial(m);
            self.terms.push((*c, r));
        }
        (start, to_u32(self.terms.len()))
    }
}

/// Interns a name as a `&'static str`, so that runtime models can hand out
/// `&[&str]` like generated ones. Each distinct name is stored once per
/// process.
fn intern(name: &str) -> &'static str {
    static NAMES: Mutex<Option<HashSet<&'static str>>> = Mutex::new(None);
    let mut guard = match NAMES.lock() {
        Ok(g) => g,
        Err(poisoned) => poisoned.into_inner(),
    };
    let set = guard.get_or_insert_with(HashSet::new);
    if let Some(&s) = set.get(name) {
        return s;
    }
    let leaked: &'static str = Box::leak(name.to_string().into_boxed_str());
    set.insert(leaked);
    leaked
}
