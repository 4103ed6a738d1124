//! The front door: [`compile`] runs the whole pipeline on a description,
//! the macro, the command line, the report and the tests alike:
//!
//! 1. parse (pest) → 2. model → 3. geometry → 4. topology
//!    ([`crate::topology::analysis::analyze_source`], an [`Analysis`]) → 5. plans (the order in
//!    which a κ = 0 mechanism's joints are solved, [`Compiled::forward`],
//!    [`Compiled::inverse`], planned on first use) → 6. code
//!    ([`crate::expand`], from a [`Compiled`]).
//!
//! A plan is the same for planar and spatial mechanisms
//! ([`pkm_runtime::plan::Plan`], made by [`crate::plan::planner`]). The
//! numeric model and the declared outputs at the file's own parameter
//! values ([`Compiled::model`], [`Compiled::outputs`], made by
//! [`crate::lowering::numeric`]) are cached the same way; at other values
//! [`Compiled::model_at`] and [`Compiled::outputs_at`] make them afresh.

use crate::diagnostics::Diagnostics;
use crate::lowering::numeric;
use crate::lowering::params::{self, ParamError};
use crate::topology::analysis::Analysis;
use pkm_runtime::model::Model;
use pkm_runtime::newton::Output;
use pkm_runtime::plan::Plan;
use std::cell::OnceCell;
use std::collections::HashMap;

/// A description compiled: its analysis, and on first use its numeric
/// model, declared outputs and plans.
#[derive(Debug)]
pub struct Compiled {
    /// Parse, model, geometry and topology.
    pub analysis: Analysis,
    model: OnceCell<Result<Model, Diagnostics>>,
    outputs: OnceCell<Result<Vec<Output>, Diagnostics>>,
    forward: OnceCell<Result<Plan, Diagnostics>>,
    inverse: OnceCell<Result<Plan, Diagnostics>>,
}

/// A compiled description at given parameter values ([`Compiled::instance`]).
#[derive(Debug, Clone)]
pub struct Instance {
    /// The numeric model at those values.
    pub model: Model,
    /// The declared outputs on that model.
    pub outputs: Vec<Output>,
    /// The overrides as given, by name (the parameters not given keep the
    /// file's values; derived ones follow).
    pub overrides: HashMap<String, f64>,
}

/// Why [`Compiled::instance`] refuses the values given.
#[derive(Debug, Clone)]
pub enum InstanceError {
    /// The file's geometry does not build (at its own values or at the overrides').
    Source(Diagnostics),
    /// An override is unknown, not finite or given twice.
    Param(ParamError),
    /// The overrides take a length through zero or a place out of the numbers.
    Dimension(String),
}

/// Compiles a description: every error in it, or its analysis with the
/// plans to come.
///
/// ```
/// let c = pkm_dsl::compile(
///     "mechanism m { planar; base R1* [a] ∥ R2 [b] ∥ R3 [c] ∥ R4 base;
///      parameters { l = 100; }
///      geometry { base { R1 = (0, 0); R4 = (3 * l, 0); } a { R1 = (0, 0); R2 = (l, 0); }
///                 b { R2 = (0, 0); R3 = (2.5 * l, 0); } c { R3 = (2 * l, 0); R4 = (0, 0); } } }",
/// )
/// .unwrap();
/// assert_eq!(c.analysis.topology.dof, 1);
/// // The forward plan: the crank given, the rest a dyad with its ± choice.
/// assert_eq!(c.forward().unwrap().choices(), 1);
/// ```
pub fn compile(source: &str) -> Result<Compiled, Diagnostics> {
    let mut analysis = crate::topology::analysis::analyze_source(source).map_err(|mut d| {
        if let Some(note) = special_geometry_hint(source, &d) {
            d.0[0].notes.push(note);
        }
        d
    })?;
    if analysis.mechanism.mobility_by_geometry.is_some() {
        // The topology of the declared dimensions, not of generic instances.
        analysis.topology = crate::lowering::mobility::accept(&analysis)?;
    }
    Ok(Compiled {
        analysis,
        model: OnceCell::new(),
        outputs: OnceCell::new(),
        forward: OnceCell::new(),
        inverse: OnceCell::new(),
    })
}

/// Where the mechanism is refused for more actuated joints than its F
/// and its declared geometry moves with as many DOF as it drives (mobility
/// from special geometry, a Bennett linkage): the declaration that would
/// accept it.
fn special_geometry_hint(source: &str, d: &Diagnostics) -> Option<String> {
    if !d.0.first()?.message.contains(" DOF but ") {
        return None;
    }
    let mut ast = crate::syntax::parser::parse(source).ok()?;
    if ast.mobility_by_geometry.is_some() {
        return None;
    }
    // The generic topology without the actuators, for its F alone.
    ast.mobility_by_geometry = Some(ast.name.span);
    let a = crate::topology::analysis::analyze_ast(&ast).ok()?;
    let model = numeric::model(&a, &HashMap::new()).ok()?;
    let special = crate::lowering::mobility::special_mobility(&a, &model).filter(|s| s.finite())?;
    (special.declared == a.mechanism.actuator_count()).then(|| {
        format!(
            "the declared dimensions move with {} DOF (the loops' rank {} at an assembly, where generic instances of \
             the declared relations give {}): mobility from special geometry; declare `mobility by geometry;` to count \
             the topology at these dimensions",
            special.declared, special.rank[0], special.rank[1]
        )
    })
}

impl Compiled {
    /// The numeric model at the file's parameter values, made on first use
    /// (an error where the geometry is incomplete).
    pub fn model(&self) -> Result<&Model, Diagnostics> {
        self.model
            .get_or_init(|| numeric::model(&self.analysis, &HashMap::new()))
            .as_ref()
            .map_err(Clone::clone)
    }

    /// The numeric model with some parameters given other values (the
    /// command line's `--param`); the file's own when `values` is empty.
    pub fn model_at(&self, values: &HashMap<String, f64>) -> Result<Model, Diagnostics> {
        if values.is_empty() {
            return self.model().cloned();
        }
        numeric::model(&self.analysis, values)
    }

    /// The declared outputs at the file's parameter values, made on first use.
    pub fn outputs(&self) -> Result<&[Output], Diagnostics> {
        self.outputs
            .get_or_init(|| numeric::newton_outputs(&self.analysis, self.model()?, &HashMap::new()))
            .as_ref()
            .map(Vec::as_slice)
            .map_err(Clone::clone)
    }

    /// The declared outputs on `model`, made at `values` by [`Self::model_at`].
    pub fn outputs_at(&self, model: &Model, values: &HashMap<String, f64>) -> Result<Vec<Output>, Diagnostics> {
        if values.is_empty() {
            return self.outputs().map(<[Output]>::to_vec);
        }
        numeric::newton_outputs(&self.analysis, model, values)
    }

    /// The model and the declared outputs at the command line's `--param`
    /// overrides `given` (name, value), every check on them made: the
    /// file's own model builds, each override names a declared parameter
    /// once with a finite value ([`params::overrides`]), takes no length
    /// through zero ([`params::check_lengths`]), and leaves every place a
    /// number ([`params::non_finite_place`]). The command line and the
    /// report both start from it.
    pub fn instance(&self, given: &[(String, f64)]) -> Result<Instance, InstanceError> {
        let nominal = self.model().map_err(InstanceError::Source)?;
        let overrides = params::overrides(&self.analysis, given).map_err(InstanceError::Param)?;
        params::check_lengths(&self.analysis, nominal, &overrides).map_err(InstanceError::Dimension)?;
        let model = self.model_at(&overrides).map_err(InstanceError::Source)?;
        if let Some(why) = params::non_finite_place(&model) {
            return Err(InstanceError::Dimension(format!("at the given parameters {why}")));
        }
        let outputs = self.outputs_at(&model, &overrides).map_err(InstanceError::Source)?;
        Ok(Instance {
            model,
            outputs,
            overrides,
        })
    }

    /// The forward plan (inputs to every joint), planned on first use.
    pub fn forward(&self) -> Result<&Plan, Diagnostics> {
        self.forward
            .get_or_init(|| crate::plan::planner::forward_plan(&self.analysis))
            .as_ref()
            .map_err(Clone::clone)
    }

    /// The inverse plan (declared outputs to every joint), planned on first use.
    pub fn inverse(&self) -> Result<&Plan, Diagnostics> {
        self.inverse
            .get_or_init(|| crate::plan::planner::inverse_plan(&self.analysis))
            .as_ref()
            .map_err(Clone::clone)
    }
}
