//! What the rotary-axis formats share (five-axis spec, "Output"): a
//! table-table five-axis machine recognised from its nominal kinematics, the
//! grid over its travel, and the fit of a controller's kinematics parameters
//! to the built machine's tool-point error, with what the parameters hold and
//! what remains.
//!
//! # The controller's frame
//!
//! A table-table controller (LinuxCNC's `xyz?c-trt-kins`, a Fanuc table
//! rotation type, ...) computes the tool point `P` in the table's frame from
//! its joints: three linear joints `J` (the tool relative to the table at
//! rotary angles 0, each along +X, +Y, +Z) and the two rotary angles. Here
//! `J = S·q_lin` (S the signed permutation that moves the tool point along
//! +X, +Y, +Z of the workpiece frame per unit of each linear variable at
//! `q = 0`, read from the nominal Jacobian) and `P = p(q) − p(0)`, `p` the
//! nominal tool point in the machine file's workpiece frame: both vanish at
//! `q = 0`, as the controller's joints and position do at its zero.
//!
//! # The fit
//!
//! A format states its model `P = f(J, a, c; θ)` (angles in degrees, as
//! controllers take them) with its pins `θ` entering affinely (every trt
//! model does: pivot points and offsets). The nominal pins `θ₀` are the
//! least-squares fit of `f` to the nominal kinematics over the grid, and
//! must reproduce it (to 1e-9 of the travel): otherwise the machine is not
//! of the kind the model describes and the export is refused. The identified
//! pins, the rotary axes' zero offsets `h` and the workpiece's zero `w` (a
//! constant translation: the work offset, which probing the part sets) are
//! the first-order least-squares fit `G·(δθ, h, w) ≈ e(q)` over the grid, `e` the position part
//! of the built machine's error in the workpiece frame and `G` the model's
//! derivatives; each part of the error (an error parameter or slot) gets its
//! share `G·G⁺·e_part`, the expressed part, and keeps the rest.

use nalgebra::{DMatrix, DVector};
use serde::Serialize;

use crate::built::{BuiltMachine, Part};
use crate::kinematics::forward::Kinematics;
use crate::model::{Frame, JointKind, Machine};
use crate::model_trait::{ErrorModel, OutOfRange};

use super::{
    along_one_axis, built_order, in_built_order, travels, Controller, ControllerError,
    ExportOptions, Term,
};

/// Nodes per linear axis in the fit grid.
const LINEAR_NODES: usize = 5;
/// Nodes per rotary axis in the fit grid.
const ROTARY_NODES: usize = 9;

/// A table-table five-axis machine as a controller sees it (module docs).
pub(crate) struct TableTable<'a, M> {
    pub controller: Controller,
    pub built: &'a BuiltMachine<M>,
    pub machine: &'a Machine,
    kin: Kinematics,
    params: Vec<f64>,
    /// Per controller axis X, Y, Z: the machine variable and its sign.
    pub linear: [(usize, f64); 3],
    /// The tilting axis (the rotary body nearer the base).
    pub tilt: usize,
    /// The rotary table (carried by the tilting axis).
    pub rotary: usize,
    /// `p(0)`.
    p0: [f64; 3],
    /// Machine variable index → built variable index.
    to_built: Vec<usize>,
    /// The fit grid, machine-ordered points.
    pub grid: Vec<Vec<f64>>,
    /// The grid's nodes per variable (machine order), for the report.
    pub nodes: Vec<(String, Vec<f64>)>,
    /// Each variable's travel (machine order).
    pub travel: Vec<(f64, f64)>,
    /// [`ExportOptions::provenance`].
    pub provenance: String,
}

/// A model of a table-table controller: its tool point from its joints and
/// its pins (affine in the pins).
pub(crate) trait TrtModel: Send + Sync {
    /// How many of the pins enter affinely (the pivot points and offsets:
    /// their nominal values are fitted to the machine file's kinematics).
    fn affine(&self) -> usize;
    /// The nominal values of the pins after those (axis directions, which
    /// the model states), identified through their first-order effect.
    fn fixed(&self) -> Vec<f64> {
        Vec::new()
    }
    /// `P = f(J, a, c; θ)`: `a` the tilting axis's and `c` the rotary
    /// table's angle in degrees.
    fn forward(&self, pins: &[f64], j: [f64; 3], a: f64, c: f64) -> [f64; 3];
    /// The joints `J` the controller drives for `P` at the angles `a`, `c`:
    /// the inverse of [`TrtModel::forward`].
    fn inverse(&self, pins: &[f64], p: [f64; 3], a: f64, c: f64) -> [f64; 3];
}

/// What a table-table controller adds to the commanded axes once the
/// identified pins, zero offsets and work offset are written (and a rotary
/// joint's positioning error table, where the format has one): at the
/// command `q` aimed at `P = f(J, a, c; θ₀)`, the joints `f⁻¹(P − w, a, c;
/// θ)` (`w` the workpiece's zero, which the work offset moves), the rotary
/// joints `h` less (the true angle is the reading plus `h`; or, where the
/// format holds the zeros in its kinematics, the transformation turned by
/// `h` instead) plus their table's trim.
pub struct KinematicsCorrection {
    pub(crate) model: Box<dyn TrtModel>,
    pub(crate) nominal: Vec<f64>,
    pub(crate) pins: Vec<f64>,
    pub(crate) zero: [f64; 2],
    pub(crate) work_offset: [f64; 3],
    pub(crate) linear: [(usize, f64); 3],
    pub(crate) tilt: usize,
    pub(crate) rotary: usize,
    /// Rotary positioning tables: (variable, nominal positions, trims), rad.
    pub(crate) comp: Vec<(usize, Vec<f64>, Vec<f64>)>,
    /// Where the zero offsets act: false, on the joints' readings (a home
    /// offset: the joints are driven `h` less); true, inside the
    /// kinematics (an axis offset: the joints read as before and the
    /// transformation turns by the reading plus `h`).
    pub(crate) zero_in_kinematics: bool,
}

impl std::fmt::Debug for KinematicsCorrection {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("KinematicsCorrection")
            .field("pins", &self.pins)
            .field("zero", &self.zero)
            .field("work_offset", &self.work_offset)
            .finish_non_exhaustive()
    }
}

impl crate::compensation::Correction for KinematicsCorrection {
    fn delta(&self, q: &[f64], delta: &mut [f64]) -> Result<(), OutOfRange> {
        let j: [f64; 3] = std::array::from_fn(|k| self.linear[k].1 * q[self.linear[k].0]);
        let (a, c) = (q[self.tilt].to_degrees(), q[self.rotary].to_degrees());
        let p = self.model.forward(&self.nominal, j, a, c);
        let p: [f64; 3] = std::array::from_fn(|k| p[k] - self.work_offset[k]);
        delta.iter_mut().for_each(|d| *d = 0.0);
        let j2 = if self.zero_in_kinematics {
            (self.model).inverse(&self.pins, p, a + self.zero[0], c + self.zero[1])
        } else {
            delta[self.tilt] = -self.zero[0].to_radians();
            delta[self.rotary] = -self.zero[1].to_radians();
            self.model.inverse(&self.pins, p, a, c)
        };
        for (k, &(v, s)) in self.linear.iter().enumerate() {
            delta[v] = s * (j2[k] - j[k]);
        }
        for (v, nominal, trim) in &self.comp {
            delta[*v] += super::interpolate_held(nominal, trim, q[*v]);
        }
        Ok(())
    }
}

/// The fit of [`TableTable::fit`].
pub(crate) struct Fit {
    /// The nominal pins.
    pub nominal: Vec<f64>,
    /// The identified pins.
    pub pins: Vec<f64>,
    /// The zero offsets of the tilting axis and the rotary table (degrees):
    /// the true angle is the reading plus these.
    pub zero: [f64; 2],
    /// The translation of the workpiece's zero `w` (mm): the tool point in
    /// the workpiece frame is the model's plus `w`. A position error of an
    /// axis that carries the workpiece moves the workpiece with it; at zero
    /// angles that is a constant, which no kinematics parameter holds and
    /// the work offset (probing the part, G54) does.
    pub work_offset: [f64; 3],
    /// The terms the pins and zeros express, each with its largest effect.
    pub expressed: Vec<Term>,
    /// The terms they leave.
    pub remaining: Vec<Term>,
    /// The largest error left (position; orientation unchanged by a
    /// position-only fit and reported beside it).
    pub residual: Term,
    /// The root mean square of the position error left over the grid (mm).
    pub residual_rms: f64,
    /// Where the largest is, by axis variable.
    pub residual_at: Vec<(String, f64)>,
}

impl Fit {
    /// The zero offsets as parameters changed from 0 (degrees; `names` the
    /// tilt's and the table's), with `unit` (the place they go, as
    /// `deg (axis offset)`).
    pub fn zero_changes(&self, names: [String; 2], unit: &'static str) -> Vec<KinematicsParameter> {
        (names.into_iter().zip(self.zero))
            .map(|(name, value)| KinematicsParameter {
                name,
                nominal: 0.0,
                value,
                unit,
            })
            .collect()
    }

    /// The change of the workpiece's zero that moves the part back, per
    /// axis X, Y, Z named `<what> X change` (mm, `unit` naming where it
    /// goes: `mm (work offset)`).
    pub fn work_offset_changes(&self, what: &str, unit: &'static str) -> Vec<KinematicsParameter> {
        (["X", "Y", "Z"].iter().zip(self.work_offset))
            .map(|(c, w)| KinematicsParameter {
                name: format!("{what} {c} change"),
                nominal: 0.0,
                value: -w,
                unit,
            })
            .collect()
    }
}

impl<'a, M: ErrorModel + Sync> TableTable<'a, M> {
    /// Recognises `machine` as a table-table machine (three linear axes,
    /// each along one of X, Y, Z at `q = 0`; two rotary axes on the
    /// workpiece branch, one carrying the other) and samples its travel.
    pub fn new(
        controller: Controller,
        built: &'a BuiltMachine<M>,
        machine: &'a Machine,
        options: &ExportOptions,
    ) -> Result<TableTable<'a, M>, ControllerError> {
        let name = controller.name();
        let takes = controller.capabilities().takes.words();
        let not = |reason: String| ControllerError::MachineKind {
            controller: name,
            takes: takes.clone(),
            machine: machine.name.clone(),
            reason,
        };
        let vars = &machine.variables;
        let rotary: Vec<usize> = (0..vars.len())
            .filter(|&i| vars[i].kind == JointKind::Rotary)
            .collect();
        if vars.len() != 5 || rotary.len() != 2 {
            return Err(not(format!(
                "it has {} linear and {} rotary axes",
                vars.len() - rotary.len(),
                rotary.len()
            )));
        }
        // The workpiece branch: the bodies from the workpiece to the root.
        let mut branch = Vec::new();
        let mut b = Some(machine.workpiece);
        while let Some(k) = b {
            branch.push(k);
            b = machine.bodies[k].parent;
        }
        let depth = |v: usize| branch.iter().position(|&k| k == vars[v].body);
        let (Some(d0), Some(d1)) = (depth(rotary[0]), depth(rotary[1])) else {
            let off = rotary.iter().find(|&&v| depth(v).is_none()).copied();
            return Err(not(format!(
                "rotary axis `{}` does not carry the workpiece (a head axis)",
                vars[off.unwrap_or(rotary[0])].name
            )));
        };
        // Nearer the workpiece: the rotary table.
        let (rot, tilt) = if d0 < d1 {
            (rotary[0], rotary[1])
        } else {
            (rotary[1], rotary[0])
        };
        let kin = Kinematics::from_machine(machine);
        let params = crate::compensation::kinematics_parameters(&kin, built);
        let zero = vec![0.0; vars.len()];
        let jac = kin.jacobian(&zero, &params);
        let mut linear = [(usize::MAX, 0.0); 3];
        for i in (0..vars.len()).filter(|i| !rotary.contains(i)) {
            let col = [jac[i][0], jac[i][1], jac[i][2]];
            let aligned = along_one_axis(col).filter(|&(k, _)| linear[k].0 == usize::MAX);
            let Some((k, sign)) = aligned else {
                return Err(not(format!(
                    "axis `{}` moves the tool point along ({:.6}, {:.6}, {:.6}) per mm at zero",
                    vars[i].name, col[0], col[1], col[2]
                )));
            };
            linear[k] = (i, sign);
        }
        let to_built = built_order(machine, built);
        let p0 = kin.pose(&zero, &params).position;
        let travel = travels(machine, options)?;
        let nodes: Vec<(String, Vec<f64>)> = (vars.iter().zip(&travel))
            .map(|(v, &(lo, hi))| {
                let n = if v.kind == JointKind::Rotary {
                    ROTARY_NODES
                } else {
                    LINEAR_NODES
                };
                let g = (0..n)
                    .map(|k| lo + (hi - lo) * k as f64 / (n - 1) as f64)
                    .collect();
                (v.name.clone(), g)
            })
            .collect();
        let total: usize = nodes.iter().map(|(_, g)| g.len()).product();
        let grid = (0..total)
            .map(|idx| {
                let mut r = idx;
                let mut q = vec![0.0; vars.len()];
                for (k, (_, g)) in nodes.iter().enumerate().rev() {
                    q[k] = g[r % g.len()];
                    r /= g.len();
                }
                q
            })
            .collect();
        Ok(TableTable {
            controller,
            built,
            machine,
            kin,
            params,
            linear,
            tilt,
            rotary: rot,
            p0,
            to_built,
            grid,
            nodes,
            travel,
            provenance: options.provenance.clone(),
        })
    }

    /// The controller's joints of machine-ordered `q`: `J` (mm) and the
    /// two angles (degrees).
    pub fn joints(&self, q: &[f64]) -> ([f64; 3], f64, f64) {
        let j = std::array::from_fn(|k| self.linear[k].1 * q[self.linear[k].0]);
        (j, q[self.tilt].to_degrees(), q[self.rotary].to_degrees())
    }

    /// `P = p(q) − p(0)`, the controller's tool point of `q`.
    pub fn position(&self, q: &[f64]) -> [f64; 3] {
        let p = self.kin.pose(q, &self.params).position;
        std::array::from_fn(|k| p[k] - self.p0[k])
    }

    /// The built machine's parts at `q`, their errors in the workpiece
    /// frame.
    pub fn parts(&self, q: &[f64]) -> Result<Vec<Part>, OutOfRange> {
        let mut parts = self.built.parts(&in_built_order(&self.to_built, q))?;
        if self.machine.frame == Frame::Tool {
            let r = self.kin.pose(q, &self.params).rotation;
            for part in &mut parts {
                let e = part.error;
                for h in 0..2 {
                    for (i, row) in r.iter().enumerate() {
                        part.error[3 * h + i] = (0..3).map(|c| row[c] * e[3 * h + c]).sum();
                    }
                }
            }
        }
        Ok(parts)
    }

    /// Fits `model`'s pins (nominal, then identified with the zero offsets)
    /// over the grid (module docs). The parts named in `elsewhere` are held
    /// by another file of the format (a rotary axis's positioning error in
    /// its table): left out of the fit and reported as expressed whole.
    pub fn fit(&self, model: &dyn TrtModel, elsewhere: &[String]) -> Result<Fit, ControllerError> {
        let m = self.grid.len();
        let joints: Vec<([f64; 3], f64, f64)> = self.grid.iter().map(|q| self.joints(q)).collect();
        let (pins, fixed) = (model.affine(), model.fixed());
        let all = pins + fixed.len();
        // Affine in the pins: f(θ) = f(0) + Σ θ_k (f(e_k) − f(0)), the
        // fixed ones at their nominal values.
        let with = |affine: Vec<f64>| -> Vec<f64> {
            affine.into_iter().chain(fixed.iter().copied()).collect()
        };
        let zero = with(vec![0.0; pins]);
        let unit = |k: usize| {
            let mut e = vec![0.0; pins];
            e[k] = 1.0;
            with(e)
        };
        let mut a = DMatrix::zeros(3 * m, pins);
        let mut b = DVector::zeros(3 * m);
        for (i, (q, &(j, ta, tc))) in self.grid.iter().zip(&joints).enumerate() {
            let f0 = model.forward(&zero, j, ta, tc);
            let p = self.position(q);
            for k in 0..pins {
                let fk = model.forward(&unit(k), j, ta, tc);
                for r in 0..3 {
                    a[(3 * i + r, k)] = fk[r] - f0[r];
                }
            }
            for r in 0..3 {
                b[3 * i + r] = p[r] - f0[r];
            }
        }
        let nominal = least_squares(&a, &b);
        let misfit = (&b - &a * &nominal).amax();
        let scale = self
            .nodes
            .iter()
            .flat_map(|(_, g)| g.iter())
            .fold(1.0f64, |s, v| s.max(v.abs()));
        if misfit.is_nan() || misfit > 1e-9 * scale {
            return Err(ControllerError::MachineKind {
                controller: self.controller.name(),
                takes: self.controller.capabilities().takes.words(),
                machine: self.machine.name.clone(),
                reason: format!(
                    "its nominal kinematics are not this model's: the best pins leave {misfit:.3e} mm over the travel"
                ),
            });
        }
        // To the nanometre: the fit reproduces the geometry to 1e-9 of the
        // travel, and a file should say 50, not 50.00000000000001.
        let nominal: Vec<f64> = with(
            (nominal.iter())
                .map(|v| (v * 1e9).round() / 1e9 + 0.0)
                .collect(),
        );
        // The identified machine: G = [∂f/∂θ, ∂f/∂a, ∂f/∂c (per degree),
        // I (the workpiece's zero)], the fixed pins' columns by central
        // differences.
        let h = 1e-4;
        let cols = all + 5;
        let mut g = DMatrix::zeros(3 * m, cols);
        let mut parts_at: Vec<Vec<Part>> = Vec::with_capacity(m);
        for (i, (q, &(j, ta, tc))) in self.grid.iter().zip(&joints).enumerate() {
            for k in 0..pins {
                for r in 0..3 {
                    g[(3 * i + r, k)] = a[(3 * i + r, k)];
                }
            }
            for k in pins..all {
                let (mut up, mut down) = (nominal.clone(), nominal.clone());
                up[k] += 1e-6;
                down[k] -= 1e-6;
                let (fu, fd) = (
                    model.forward(&up, j, ta, tc),
                    model.forward(&down, j, ta, tc),
                );
                for r in 0..3 {
                    g[(3 * i + r, k)] = (fu[r] - fd[r]) / 2e-6;
                }
            }
            for (c, (da, dc)) in [(h, 0.0), (0.0, h)].into_iter().enumerate() {
                let up = model.forward(&nominal, j, ta + da, tc + dc);
                let down = model.forward(&nominal, j, ta - da, tc - dc);
                for r in 0..3 {
                    g[(3 * i + r, all + c)] = (up[r] - down[r]) / (2.0 * h);
                }
            }
            for r in 0..3 {
                g[(3 * i + r, all + 2 + r)] = 1.0;
            }
            parts_at.push(self.parts(q).map_err(|e| self.out_of_table(e))?);
        }
        let names: Vec<String> = parts_at
            .first()
            .map(|p| p.iter().map(|x| x.name.clone()).collect())
            .unwrap_or_default();
        let svd = g.clone().svd(true, true);
        let tol = 1e-12 * svd.singular_values.max();
        let solve = |rhs: &DVector<f64>| -> DVector<f64> {
            svd.solve(rhs, tol).unwrap_or_else(|_| DVector::zeros(cols))
        };
        let mut total = DVector::zeros(cols);
        let mut expressed: Vec<Term> = Vec::new();
        let mut remaining: Vec<Term> = Vec::new();
        let mut left = vec![[0.0; 6]; m];
        for (p, name) in names.iter().enumerate() {
            if elsewhere.contains(name) {
                let mut held = term(name);
                for at in &parts_at {
                    held.position = held.position.max(norm(&at[p].error[..3]));
                    held.orientation = held.orientation.max(norm(&at[p].error[3..]));
                }
                expressed.push(held);
                continue;
            }
            let e = DVector::from_fn(3 * m, |row, _| parts_at[row / 3][p].error[row % 3]);
            let x = solve(&e);
            let share = &g * &x;
            let (mut held, mut rest) = (term(name), term(name));
            for i in 0..m {
                let err = parts_at[i][p].error;
                let s: [f64; 3] = std::array::from_fn(|r| share[3 * i + r]);
                let r: [f64; 6] =
                    std::array::from_fn(|c| if c < 3 { err[c] - s[c] } else { err[c] });
                held.position = held.position.max(norm(&s));
                rest.position = rest.position.max(norm(&r[..3]));
                rest.orientation = rest.orientation.max(norm(&r[3..]));
                for c in 0..6 {
                    left[i][c] += r[c];
                }
            }
            total += x;
            // Shares below the round-off of the projection are none.
            let size = held.position.max(rest.position);
            if held.position > 1e-9 * size {
                expressed.push(held);
            }
            if rest.position > 1e-9 * size || rest.orientation > 0.0 {
                remaining.push(rest);
            }
        }
        let mut residual = term("residual");
        let (mut sum2, mut worst, mut at) = (0.0, -1.0, 0);
        for (i, l) in left.iter().enumerate() {
            let p = norm(&l[..3]);
            sum2 += p * p;
            if p > worst {
                worst = p;
                at = i;
            }
            residual.position = residual.position.max(p);
            residual.orientation = residual.orientation.max(norm(&l[3..]));
        }
        let residual_at = (self.machine.variables.iter())
            .zip(&self.grid[at])
            .map(|(v, x)| (v.name.clone(), *x))
            .collect();
        Ok(Fit {
            pins: (0..all).map(|k| nominal[k] + total[k]).collect(),
            nominal,
            zero: [total[all], total[all + 1]],
            work_offset: [total[all + 2], total[all + 3], total[all + 4]],
            expressed,
            remaining,
            residual,
            residual_rms: (sum2 / m.max(1) as f64).sqrt(),
            residual_at,
        })
    }

    fn out_of_table(&self, e: OutOfRange) -> ControllerError {
        let k = self.machine.variable_index(&e.variable).unwrap_or(0);
        let g = &self.nodes[k].1;
        ControllerError::OutOfTable {
            variable: e.variable.clone(),
            lo: g[0],
            hi: g[g.len() - 1],
            source: Box::new(e),
        }
    }
}

/// What a rotary format writes besides its files: its kinematics' name,
/// the parameters and notes of the report, where its zeros act, its rotary
/// tables and their resampling.
pub(crate) struct Written {
    /// The controller's kinematics, for the report.
    pub module: String,
    /// The parameters written (nominal and identified).
    pub parameters: Vec<KinematicsParameter>,
    /// What a user must know.
    pub notes: Vec<String>,
    /// [`KinematicsCorrection::zero_in_kinematics`].
    pub zero_in_kinematics: bool,
    /// Rotary positioning tables: (variable, nominal positions, trims), rad.
    pub comp: Vec<(usize, Vec<f64>, Vec<f64>)>,
    /// Their largest resampling difference (rad).
    pub resampling: f64,
}

impl<'a, M: ErrorModel + Sync> TableTable<'a, M> {
    /// The first of `candidates` (a model and how to name it) whose nominal
    /// kinematics are the machine's, fitted ([`TableTable::fit`]); none,
    /// the machine is refused naming each one's misfit after `none`.
    pub fn fit_first<T: TrtModel + Copy>(
        &self,
        candidates: impl IntoIterator<Item = (T, String)>,
        elsewhere: &[String],
        none: &str,
    ) -> Result<(T, Fit), ControllerError> {
        let mut tried = Vec::new();
        for (model, label) in candidates {
            match self.fit(&model, elsewhere) {
                Ok(fit) => return Ok((model, fit)),
                Err(ControllerError::MachineKind { reason, .. }) => tried.push(format!(
                    "{label}: {}",
                    reason.trim_start_matches("its nominal kinematics are not this model's: ")
                )),
                Err(e) => return Err(e),
            }
        }
        Err(ControllerError::MachineKind {
            controller: self.controller.name(),
            takes: self.controller.capabilities().takes.words(),
            machine: self.machine.name.clone(),
            reason: format!("{none} ({})", tried.join("; ")),
        })
    }

    /// Rounds `fit`'s identified pins to `places` decimals (the format's
    /// resolution: what its file holds, so that the correction is the
    /// file's) and returns the largest tool-point shift over the grid that
    /// makes (mm).
    pub fn round_pins(&self, model: &dyn TrtModel, fit: &mut Fit, places: i32) -> f64 {
        let step = 10f64.powi(-places);
        let rounded: Vec<f64> = (fit.pins.iter())
            .map(|v| (v / step).round() * step)
            .collect();
        let mut shift: f64 = 0.0;
        for q in &self.grid {
            let (j, a, c) = self.joints(q);
            let (before, after) = (
                model.forward(&fit.pins, j, a, c),
                model.forward(&rounded, j, a, c),
            );
            shift = shift.max(norm(&std::array::from_fn::<f64, 3, _>(|i| {
                after[i] - before[i]
            })));
        }
        fit.pins = rounded;
        shift
    }

    /// The controller's axes: X, Y, Z as the machine's variables (`-` where
    /// one is turned) and the two rotary axes under the names given.
    pub fn axis_names(&self, tilt: &str, rotary: &str) -> Vec<(String, String)> {
        let var = |i: usize| self.machine.variables[i].name.clone();
        let mut axes: Vec<(String, String)> = (0..3)
            .map(|k| {
                let (v, s) = self.linear[k];
                let sign = if s < 0.0 { "-" } else { "" };
                (["X", "Y", "Z"][k].to_string(), format!("{sign}{}", var(v)))
            })
            .collect();
        axes.push((tilt.to_string(), var(self.tilt)));
        axes.push((rotary.to_string(), var(self.rotary)));
        axes
    }

    /// The [`Export`] of a rotary format: its `files`, the report of `fit`
    /// with what it `written`, and the correction the controller applies
    /// with `model`.
    pub fn finish<T: TrtModel + 'static>(
        &self,
        files: Vec<crate::compensation::ExportedFile>,
        model: T,
        fit: Fit,
        axes: Vec<(String, String)>,
        written: Written,
    ) -> super::Export {
        let correction = KinematicsCorrection {
            model: Box::new(model),
            nominal: fit.nominal.clone(),
            pins: fit.pins.clone(),
            zero: fit.zero,
            work_offset: fit.work_offset,
            linear: self.linear,
            tilt: self.tilt,
            rotary: self.rotary,
            comp: written.comp,
            zero_in_kinematics: written.zero_in_kinematics,
        };
        super::Export {
            report: super::FormatReport {
                controller: self.controller,
                machine: self.machine.name.clone(),
                files: files.iter().map(|f| f.name.clone()).collect(),
                axes: Vec::new(),
                expressed: fit.expressed,
                remaining: fit.remaining,
                residual: fit.residual,
                resampling: written.resampling,
                check_grid: self.nodes.clone(),
                directions: Vec::new(),
                kinematics: Some(KinematicsReport {
                    module: written.module,
                    axes,
                    parameters: written.parameters,
                    notes: written.notes,
                    residual_rms: fit.residual_rms,
                    residual_at: fit.residual_at,
                }),
            },
            files,
            correction: Box::new(correction),
        }
    }
}

/// Rotation of `x` by `deg` degrees right-handed about `axis` (normalised;
/// Rodrigues).
pub(crate) fn rotate(axis: [f64; 3], deg: f64, x: [f64; 3]) -> [f64; 3] {
    let n = (axis.iter().map(|a| a * a).sum::<f64>()).sqrt();
    let k: [f64; 3] = std::array::from_fn(|i| axis[i] / n);
    let (s, c) = deg.to_radians().sin_cos();
    let dot: f64 = (0..3).map(|i| k[i] * x[i]).sum();
    let cross = [
        k[1] * x[2] - k[2] * x[1],
        k[2] * x[0] - k[0] * x[2],
        k[0] * x[1] - k[1] * x[0],
    ];
    std::array::from_fn(|i| x[i] * c + cross[i] * s + k[i] * dot * (1.0 - c))
}

/// The axis orientations a table-table format tries on the machine: the
/// tilting axis along X or Y, the rotary table along Z, each with a sense
/// (`±1`): `[(frame axis, sense); 2]`, in the order tried.
pub(crate) fn orientations() -> impl Iterator<Item = [(usize, f64); 2]> {
    [0usize, 1].into_iter().flat_map(|k| {
        [-1.0, 1.0]
            .into_iter()
            .flat_map(move |s1| [-1.0, 1.0].into_iter().map(move |s2| [(k, s1), (2, s2)]))
    })
}

/// A README's closing sections: under `zeros` the zero changes (the
/// parameters of unit `zero_unit`), under `work` the workpiece's zero
/// changes (unit `mm (…)`), one `name = value` line each.
pub(crate) fn changes_text(
    parameters: &[KinematicsParameter],
    zero_unit: &str,
    zeros: &str,
    work: &str,
) -> String {
    let mut text = String::new();
    for (heading, keep) in [
        (
            zeros,
            &(|p: &KinematicsParameter| p.unit == zero_unit)
                as &dyn Fn(&KinematicsParameter) -> bool,
        ),
        (work, &|p: &KinematicsParameter| p.unit.starts_with("mm (")),
    ] {
        text.push_str(&format!("\n{heading}:\n"));
        for p in parameters.iter().filter(|p| keep(p)) {
            text.push_str(&format!("{} = {}\n", p.name, super::num(p.value)));
        }
    }
    text
}

/// A term named `name` of size 0.
fn term(name: &str) -> Term {
    Term {
        name: name.to_string(),
        position: 0.0,
        orientation: 0.0,
    }
}

fn norm(v: &[f64]) -> f64 {
    v.iter().map(|x| x * x).sum::<f64>().sqrt()
}

/// The minimum-norm least-squares solution of `a x ≈ b` (SVD).
fn least_squares(a: &DMatrix<f64>, b: &DVector<f64>) -> DVector<f64> {
    let svd = a.clone().svd(true, true);
    let tol = 1e-12 * svd.singular_values.max();
    svd.solve(b, tol)
        .unwrap_or_else(|_| DVector::zeros(a.ncols()))
}

/// The report's account of a rotary format's kinematics: which module,
/// the pins written (nominal and identified), the zero offsets, and what
/// the controller's own kinematics were checked against.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct KinematicsReport {
    /// The controller's kinematics (`xyzac-trt-kins`, ...).
    pub module: String,
    /// The machine's axes as the controller names them: its variable per
    /// controller axis letter.
    pub axes: Vec<(String, String)>,
    /// Each parameter written: its name, the nominal value (from the
    /// machine file) and the identified one.
    pub parameters: Vec<KinematicsParameter>,
    /// What the format says about itself and this machine that a user must
    /// know (a setting, a known defect of the controller's kinematics).
    pub notes: Vec<String>,
    /// The root mean square position error the pins leave over the grid
    /// (first order, mm).
    pub residual_rms: f64,
    /// Where the largest is (axis variable values, machine units).
    pub residual_at: Vec<(String, f64)>,
}

/// One parameter a rotary format writes.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct KinematicsParameter {
    /// Its name in the controller.
    pub name: String,
    /// The value for the nominal machine.
    pub nominal: f64,
    /// The value for the identified machine.
    pub value: f64,
    /// Its unit (`mm`, `deg`, ...).
    pub unit: &'static str,
}
