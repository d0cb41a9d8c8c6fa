//! `chain._chain`: the compiled core of the `chain` Python package.
//!
//! A thin layer over the libraries (`chain_core`, `reliability`, the `chain`
//! facade): [`Model`] holds a loaded machine and its compiled tape; the batch
//! evaluations ([`Model::sensitivity`], [`Model::error`], [`Model::nominal`])
//! take C-contiguous float64 arrays and run over all cores with the GIL
//! released; every other capability returns its result document as JSON
//! text, the document the CLI prints for the same input (`json.loads` on the
//! Python side). Adding a capability is a `#[pyfunction]` taking
//! `&Model` and returning `PyResult<String>` from the library's document, in
//! the module of its group (one file per group of commands, registered in
//! [`_chain`] below), plus its Python method and stub entry (`python/chain/`).
//!
//! Nothing panics on bad input: shapes, non-finite values and names are
//! checked before any evaluation and refused with `ValueError`; machine-file
//! problems raise `MachineError` (a `ValueError`) with `file`, `line`,
//! `column` and `key`.

mod circular;
mod compensate;
mod export;
mod inverse;
mod measured;
mod motion;
mod path;
mod positioning;
mod report;
mod thermal;
use std::mem::MaybeUninit;

use chain::ops::choice::Choice;
use chain::ops::source::Source;
use chain::ops::study::describe;
use chain::ops::Worded;
use chain_core::model::{Frame, Machine, Origin};
use chain_core::{CompiledModel, Diagnostics, ErrorModel};
use numpy::{PyArray1, PyArrayMethods, PyReadonlyArray2, PyUntypedArrayMethods};
use pyo3::create_exception;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use rayon::prelude::*;
use reliability::ReliabilityError;

mod allocate;
mod sensitivity;
mod study;

create_exception!(
    _chain,
    MachineError,
    PyValueError,
    "A problem in a machine file (or a value given for it): `file`, `line`, `column` (0 when not located) and `key`."
);

/// Points per parallel block of the batch evaluations.
const BLOCK: usize = 1024;

/// A new uninitialised float64 numpy array of `len` values and its data as
/// a slice of `MaybeUninit` for the workers to initialise (numpy's allocator
/// obtains it, so the pages are first touched by the workers that write
/// them, and large arrays get numpy's transparent-huge-page advice).
fn uninit_array(py: Python<'_>, len: usize) -> (Bound<'_, PyArray1<f64>>, &mut [MaybeUninit<f64>]) {
    // SAFETY: `PyArray1::new` returns an array of `len` float64 values whose
    // memory numpy owns and nobody else references yet; it is viewed as
    // `MaybeUninit` (no value is read before it is written, `par_rows`
    // writes every one) for as long as the caller holds the array.
    unsafe {
        let array = PyArray1::<f64>::new(py, len, false);
        let data = array.data() as *mut MaybeUninit<f64>;
        let slice = if len == 0 {
            &mut []
        } else {
            std::slice::from_raw_parts_mut(data, len)
        };
        (array, slice)
    }
}

/// `out` with every value set to zero, as the `f64`s it then holds.
fn zeroed(out: &mut [MaybeUninit<f64>]) -> &mut [f64] {
    out.fill(MaybeUninit::new(0.0));
    // SAFETY: every value was just initialised, and `MaybeUninit<f64>` has
    // the layout of `f64`.
    unsafe { &mut *(out as *mut [MaybeUninit<f64>] as *mut [f64]) }
}

/// Writes every row of `out` (rows of `width` values) as `row(i, values)`
/// does, point `i` after point, in parallel blocks of [`BLOCK`] rows; each
/// row is zeroed first (in cache), so `row` sees initialised values and
/// `out` is wholly initialised on return. The one loop of the batch
/// evaluations (sensitivity, error, nominal).
fn par_rows(out: &mut [MaybeUninit<f64>], width: usize, row: impl Fn(usize, &mut [f64]) + Sync) {
    if width == 0 {
        return;
    }
    out.par_chunks_mut(width * BLOCK)
        .enumerate()
        .for_each(|(b, chunk)| {
            for (k, values) in chunk.chunks_mut(width).enumerate() {
                values.fill(MaybeUninit::new(0.0));
                // SAFETY: every value of `values` was just initialised, and
                // `MaybeUninit<f64>` has the layout of `f64`.
                let values = unsafe { &mut *(values as *mut [MaybeUninit<f64>] as *mut [f64]) };
                row(b * BLOCK + k, values);
            }
        });
}

/// A `MachineError` with its location attributes set.
pub(crate) fn machine_error(
    py: Python<'_>,
    message: String,
    file: &str,
    origin: Option<&Origin>,
    errors: Vec<String>,
) -> PyErr {
    let err = MachineError::new_err(message.clone());
    let value = err.value(py);
    let (line, column, key) =
        origin.map_or((0, 0, String::new()), |o| (o.line, o.column, o.key.clone()));
    let set = || -> PyResult<()> {
        value.setattr("message", message)?;
        value.setattr("file", file)?;
        value.setattr("line", line)?;
        value.setattr("column", column)?;
        value.setattr("key", key)?;
        value.setattr("errors", errors)?;
        Ok(())
    };
    match set() {
        Ok(()) => err,
        Err(e) => e,
    }
}

/// The loader's diagnostics as a `MachineError`: the CLI's message (the
/// first error, and how many more), located at the first error.
pub(crate) fn load_error(py: Python<'_>, d: &Diagnostics) -> PyErr {
    let first = d.first();
    let all = d.iter().map(|e| e.to_string()).collect();
    machine_error(py, d.to_string(), d.file(), Some(&first.origin), all)
}

/// A reliability error as a `MachineError`, worded as the CLI words it.
pub(crate) fn study_error(py: Python<'_>, err: &ReliabilityError, file: &str) -> PyErr {
    let d = describe(err, file);
    let origin = d.origin.filter(|o| o.line > 0);
    let mut message = d.message.clone();
    if !d.help.is_empty() {
        message = format!("{message}\nhelp: {}", d.help);
    }
    machine_error(py, message, file, origin, vec![d.message])
}

/// A table's refusal ([`chain::ops::tables`]) as the CLI words it: a
/// `MachineError` where its columns name what the machine lacks, a
/// `ValueError` otherwise.
pub(crate) fn table_error(
    py: Python<'_>,
    model: &Model,
    e: chain::ops::tables::TableError,
) -> PyErr {
    match e {
        chain::ops::tables::TableError::Resolve(e) => resolve_error(py, model, e),
        e => value_error(e.to_string()),
    }
}

/// An option refused by `chain::ops::resolve`, with the CLI's message: an
/// unknown name as `MachineError` naming the machine file, a bad value as
/// `ValueError`.
pub(crate) fn resolve_error(
    py: Python<'_>,
    model: &Model,
    e: chain::ops::resolve::ResolveError,
) -> PyErr {
    let message = e.with_help();
    if e.names_the_machine() {
        machine_error(py, message, &model.file, None, vec![e.to_string()])
    } else {
        value_error(message)
    }
}

/// A `ValueError` with `message`.
pub(crate) fn value_error(message: impl Into<String>) -> PyErr {
    PyValueError::new_err(message.into())
}

/// The serialised document (non-finite numbers become `null`, as in the CLI).
pub(crate) fn to_json<T: serde::Serialize>(doc: &T) -> PyResult<String> {
    serde_json::to_string(doc).map_err(|e| value_error(format!("cannot serialise the result: {e}")))
}

/// Refuses the first non-finite value of `values` (`what` names the array).
pub(crate) fn check_finite(values: &[f64], width: usize, what: &str) -> PyResult<()> {
    let bad = values.par_iter().position_first(|v| !v.is_finite());
    match bad {
        None => Ok(()),
        Some(i) if width > 0 => Err(value_error(format!(
            "{what} has a non-finite value ({}) at row {}, column {}",
            values[i],
            i / width,
            i % width
        ))),
        Some(i) => Err(value_error(format!(
            "{what} has a non-finite value ({}) at index {i}",
            values[i]
        ))),
    }
}

/// A loaded machine file and its compiled error model.
#[pyclass(module = "chain._chain", frozen)]
pub(crate) struct Model {
    pub(crate) machine: Machine,
    pub(crate) model: CompiledModel,
    /// The file name diagnostics name.
    pub(crate) file: String,
}

impl Model {
    fn new(machine: Machine, file: String) -> Model {
        let model = chain_core::compile(&machine);
        Model {
            machine,
            model,
            file,
        }
    }

    /// The parameter values: the file's, overridden by `overrides`, checked
    /// by `--param`'s rule ([`chain::ops::resolve::Parameters`]); every
    /// symbolic parameter needs one.
    pub(crate) fn parameter_vector(
        &self,
        py: Python<'_>,
        overrides: &[(String, f64)],
    ) -> PyResult<Vec<f64>> {
        let given = chain::ops::resolve::Parameters::new(&self.machine, overrides)
            .map_err(|e| resolve_error(py, self, e))?;
        given.values().map_err(|e| study_error(py, &e, &self.file))
    }

    /// The points of `q` (rows of `V` values) as a flat slice and their count.
    pub(crate) fn points<'a>(
        &self,
        q: &'a PyReadonlyArray2<'_, f64>,
    ) -> PyResult<(&'a [f64], usize)> {
        let v = self.model.variables().len();
        let shape = q.shape();
        if shape[1] != v {
            return Err(value_error(format!(
                "q must have {v} values per point (the variables {}), found {}",
                self.model.variables().join(", "),
                shape[1]
            )));
        }
        let flat = q
            .as_slice()
            .map_err(|_| value_error("q must be a C-contiguous float64 array"))?;
        check_finite(flat, v, "q")?;
        Ok((flat, shape[0]))
    }
}

#[pymethods]
impl Model {
    /// Loads a machine file.
    #[staticmethod]
    fn load(py: Python<'_>, path: &str) -> PyResult<Model> {
        let machine =
            chain_core::load_file(std::path::Path::new(path)).map_err(|d| load_error(py, &d))?;
        let file = machine.file.clone().unwrap_or_else(|| path.to_string());
        Ok(Model::new(machine, file))
    }

    /// Loads a machine from YAML text (`file` names it in diagnostics).
    #[staticmethod]
    fn from_yaml(py: Python<'_>, text: &str, file: &str) -> PyResult<Model> {
        let machine = chain_core::load_str(text, file).map_err(|d| load_error(py, &d))?;
        Ok(Model::new(machine, file.to_string()))
    }

    /// The machine's name.
    #[getter]
    fn name(&self) -> String {
        self.machine.name.clone()
    }

    /// The file name diagnostics use.
    #[getter]
    fn file(&self) -> String {
        self.file.clone()
    }

    /// The axis variables, in model order.
    #[getter]
    fn variables(&self) -> Vec<String> {
        self.model
            .variables()
            .iter()
            .map(|s| s.to_string())
            .collect()
    }

    /// The parameters and their file values (`None`: symbolic).
    #[getter]
    fn parameters(&self) -> Vec<(String, Option<f64>)> {
        self.model
            .parameters()
            .iter()
            .zip(self.model.parameter_values())
            .map(|(n, v)| (n.to_string(), *v))
            .collect()
    }

    /// The error parameters, in model order.
    #[getter]
    fn errors(&self) -> Vec<String> {
        self.model.errors().iter().map(|s| s.to_string()).collect()
    }

    /// `chain derive --format json` (frame: `None` for the file's, or
    /// `"tool"` / `"workpiece"`).
    #[pyo3(signature = (frame=None))]
    fn derive_json(&self, frame: Option<&str>) -> PyResult<String> {
        use chain::ops::derive::{self, DeriveRequest};
        let frame = frame.map(choice::<Frame>).transpose()?;
        to_json(&derive::run(&self.machine, &DeriveRequest { frame }))
    }

    /// The sensitivity `∂E/∂e` at each row of `q` (`(N, V)`): a flat
    /// `N·6·N_err` array (row-major `(N, 6, N_err)`), computed in parallel
    /// blocks with the GIL released, written once into numpy's zeroed
    /// (calloc'ed, so lazily zeroed by the kernel) array.
    #[pyo3(signature = (q, params))]
    fn sensitivity<'py>(
        &self,
        py: Python<'py>,
        q: PyReadonlyArray2<'py, f64>,
        params: Vec<(String, f64)>,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let n = q.shape()[0];
        let array = PyArray1::<f64>::zeros(py, n * 6 * self.model.errors().len(), false);
        {
            let mut out = array.readwrite();
            let out = out
                .as_slice_mut()
                .map_err(|_| value_error("the output array is not contiguous"))?;
            self.sensitivity_fill(py, &q, &params, out)?;
        }
        Ok(array)
    }

    /// [`Model::sensitivity`] written into the caller's array `out` (the
    /// flat view of a C-contiguous float64 array of `N·6·N_err` values,
    /// checked here): `Machine.sensitivity(q, out=...)`.
    #[pyo3(signature = (q, params, out))]
    fn sensitivity_into<'py>(
        &self,
        py: Python<'py>,
        q: PyReadonlyArray2<'py, f64>,
        params: Vec<(String, f64)>,
        out: Bound<'py, numpy::PyArrayDyn<f64>>,
    ) -> PyResult<()> {
        let want = q.shape()[0] * 6 * self.model.errors().len();
        let mut out = out
            .try_readwrite()
            .map_err(|_| value_error("out must be a writeable array not borrowed elsewhere"))?;
        let out = out
            .as_slice_mut()
            .map_err(|_| value_error("out must be a C-contiguous float64 array"))?;
        if out.len() != want {
            return Err(value_error(format!(
                "out holds {} values, expected {want} (one 6 x {} matrix per point)",
                out.len(),
                self.model.errors().len()
            )));
        }
        self.sensitivity_fill(py, &q, &params, out)
    }

    /// The error `E = S·e` at each row of `q` (`(N, V)`) with the errors of
    /// the matching row of `e` (`(N, N_err)`, or `(1, N_err)` for all rows):
    /// a flat `N·6` array, in parallel with the GIL released.
    #[pyo3(signature = (q, e, params))]
    fn error<'py>(
        &self,
        py: Python<'py>,
        q: PyReadonlyArray2<'py, f64>,
        e: PyReadonlyArray2<'py, f64>,
        params: Vec<(String, f64)>,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let p = self.parameter_vector(py, &params)?;
        let (q, n) = self.points(&q)?;
        let (v, ne) = (self.model.variables().len(), self.model.errors().len());
        let shape = e.shape();
        if shape[1] != ne {
            return Err(value_error(format!(
                "e must have {ne} values per point (the errors of the model), found {}",
                shape[1]
            )));
        }
        if shape[0] != n && shape[0] != 1 {
            return Err(value_error(format!(
                "e has {} rows for {n} points of q (give one row, or one per point)",
                shape[0]
            )));
        }
        let e_rows = shape[0];
        let e = e
            .as_slice()
            .map_err(|_| value_error("e must be a C-contiguous float64 array"))?;
        check_finite(e, ne, "e")?;
        let model = &self.model;
        let (array, out) = uninit_array(py, n * 6);
        // One row of `e` for every point, or one per point.
        let e = if e_rows == 1 { &e[..ne] } else { e };
        py.allow_threads(|| {
            if v == 0 {
                // No coordinates to count the points by: one after another.
                par_rows(out, 6, |i, row| {
                    let j = if e_rows == 1 { 0 } else { i };
                    if let Ok(row) = <&mut [f64; 6]>::try_from(row) {
                        model.error(&[], &p, &e[j * ne..(j + 1) * ne], row);
                    }
                });
                return Ok(());
            }
            let out = zeroed(out);
            // The batched tape, in parallel blocks.
            model.error_batch(q, &p, e, out)
        })
        .map_err(|e| value_error(e.to_string()))?;
        Ok(array)
    }

    /// The nominal pose at each row of `q`: a flat `N·12` array, per point
    /// the rotation (row-major 3×3) then the position.
    #[pyo3(signature = (q, params))]
    fn nominal<'py>(
        &self,
        py: Python<'py>,
        q: PyReadonlyArray2<'py, f64>,
        params: Vec<(String, f64)>,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let p = self.parameter_vector(py, &params)?;
        let (q, n) = self.points(&q)?;
        let v = self.model.variables().len();
        let model = &self.model;
        let (array, out) = uninit_array(py, n * 12);
        py.allow_threads(|| {
            par_rows(out, 12, |i, row| {
                let pose = model.nominal(&q[i * v..(i + 1) * v], &p);
                for r in 0..3 {
                    row[3 * r..3 * r + 3].copy_from_slice(&pose.rotation[r]);
                }
                row[9..12].copy_from_slice(&pose.position);
            })
        });
        Ok(array)
    }

    /// The benchmark's reference (python/benches/sensitivity.py): the runtime
    /// tape's sensitivity at each row of `q`, one point after another on one
    /// thread into one reused 6×N_err buffer (no output array, no threads).
    /// Returns the seconds it took and the sum of all entries.
    #[pyo3(signature = (q, params))]
    fn tape_per_point<'py>(
        &self,
        py: Python<'py>,
        q: PyReadonlyArray2<'py, f64>,
        params: Vec<(String, f64)>,
    ) -> PyResult<(f64, f64)> {
        let p = self.parameter_vector(py, &params)?;
        let (q, n) = self.points(&q)?;
        let (v, ne) = (self.model.variables().len(), self.model.errors().len());
        let model = &self.model;
        Ok(py.allow_threads(|| {
            let mut out = vec![0.0; 6 * ne];
            let mut sum = 0.0;
            let start = std::time::Instant::now();
            for i in 0..n {
                model.sensitivity(&q[i * v..(i + 1) * v], &p, &mut out);
                sum += out.iter().sum::<f64>();
            }
            (start.elapsed().as_secs_f64(), sum)
        }))
    }
}

impl Model {
    /// Every point's sensitivity into `out` (`N·6·N_err` values, any
    /// previous contents): the batched tape in parallel blocks, the GIL
    /// released. The one body of `sensitivity` and `sensitivity_into`.
    fn sensitivity_fill(
        &self,
        py: Python<'_>,
        q: &PyReadonlyArray2<'_, f64>,
        params: &[(String, f64)],
        out: &mut [f64],
    ) -> PyResult<()> {
        let p = self.parameter_vector(py, params)?;
        let (q, _) = self.points(q)?;
        let width = 6 * self.model.errors().len();
        let model = &self.model;
        let v = model.variables().len();
        py.allow_threads(|| {
            if v == 0 {
                // No coordinates to count the points by: one after another.
                if width > 0 {
                    out.par_chunks_mut(width)
                        .for_each(|row| model.sensitivity(&[], &p, row));
                }
                return Ok(());
            }
            // The batched tape, in parallel blocks (`points` gave whole rows).
            model.sensitivity_batch(q, &p, out)
        })
        .map_err(|e| value_error(e.to_string()))
    }
}

/// A study's refusal: a reliability error located in the machine file, an
/// option as `resolve_error`, the posterior located in the values file, an
/// approach the values do not have as `ValueError`.
pub(crate) fn study_failure(
    py: Python<'_>,
    model: &Model,
    e: chain::ops::study::StudyError,
) -> PyErr {
    use chain::ops::study::StudyError;
    use reliability::PosteriorError;
    match e {
        StudyError::Reliability(e) => study_error(py, &e, &model.file),
        StudyError::Resolve(e) => resolve_error(py, model, e),
        StudyError::Posterior(PosteriorError::Values(v)) => load_error(py, v.diagnostics()),
        StudyError::Posterior(PosteriorError::File(d)) => load_error(py, &d),
        StudyError::Posterior(PosteriorError::Reliability(e)) => study_error(py, &e, &model.file),
        e @ (StudyError::Posterior(_) | StudyError::Approach { .. }) => value_error(e.with_help()),
    }
}

/// `given` as one of `T`'s values, spelt as the CLI spells them, or the
/// CLI's refusal ([`chain::ops::choice::Choice::parse`]).
pub(crate) fn choice<T: Choice>(given: &str) -> PyResult<T> {
    T::parse(given).map_err(|e| value_error(e.to_string()))
}

/// `sided` as the CLI's `--sided` (`upper` or `two`).
pub(crate) fn sided_named(sided: Option<&str>) -> PyResult<Option<chain_core::model::Sided>> {
    sided.map(choice).transpose()
}

/// A file Python gives as a `path` or as its `text` named `name`
/// ([`Source::given`]).
pub(crate) fn source<'a>(
    path: Option<&'a str>,
    text: Option<&'a str>,
    name: &'a str,
) -> PyResult<Source<'a>> {
    Source::given(path, text, name).map_err(|e| value_error(e.to_string()))
}

/// A file argument given as one tuple `(path, text, name)`: a path, or its
/// text named `name` (`poses_file`, `axes_file`).
#[derive(FromPyObject)]
pub(crate) struct FileInput(Option<String>, Option<String>, String);

impl FileInput {
    /// The file as ops reads it.
    pub(crate) fn source(&self) -> PyResult<Source<'_>> {
        source(self.0.as_deref(), self.1.as_deref(), &self.2)
    }
}

/// The compiled core of the `chain` package.
#[pymodule]
fn _chain(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<Model>()?;
    m.add("MachineError", m.py().get_type::<MachineError>())?;
    m.add_function(wrap_pyfunction!(measured::identify_json, m)?)?;
    m.add_function(wrap_pyfunction!(measured::plan_json, m)?)?;
    m.add_function(wrap_pyfunction!(measured::map_json, m)?)?;
    m.add_function(wrap_pyfunction!(study::reliability_json, m)?)?;
    m.add_function(wrap_pyfunction!(study::sobol_json, m)?)?;
    m.add_function(wrap_pyfunction!(
        sensitivity::sensitivity_reliability_json,
        m
    )?)?;
    m.add_function(wrap_pyfunction!(sensitivity::geometric_json, m)?)?;
    m.add_function(wrap_pyfunction!(allocate::allocate_json, m)?)?;
    m.add_function(wrap_pyfunction!(positioning::positioning_json, m)?)?;
    m.add_function(wrap_pyfunction!(thermal::thermal_json, m)?)?;
    m.add_function(wrap_pyfunction!(circular::circular_json, m)?)?;
    m.add_function(wrap_pyfunction!(report::report_html, m)?)?;
    m.add_function(wrap_pyfunction!(inverse::inverse_json, m)?)?;
    m.add_function(wrap_pyfunction!(path::path_json, m)?)?;
    m.add_function(wrap_pyfunction!(export::export_json, m)?)?;
    m.add_function(wrap_pyfunction!(motion::motion_json, m)?)?;
    m.add_function(wrap_pyfunction!(compensate::compensate_json, m)?)?;
    Ok(())
}
