//! The reference's motion (the inputs' rates and accelerations, every
//! joint's from them) and the actuators' forces that hold the mechanism
//! there ([`holding`], pkm's Newton–Euler): the keyframe's motor inputs.

use super::Options;
use crate::cli::failure::{Failure, Kind};
use crate::cli::solve::{input_values, Request};
use pkm_runtime::mass_properties::Loading;
use pkm_runtime::model::Model;

/// The reference's motion: every joint's rate and acceleration from the
/// inputs' (`--rates`, `--accels`; zeros, at rest, where not given), and
/// the inputs' in the model's input order, as Newton–Euler takes them.
pub(super) struct Motion {
    pub(super) given: bool,
    pub(super) input_rates: Vec<f64>,
    pub(super) input_accels: Vec<f64>,
    pub(super) rates: Vec<f64>,
    pub(super) accels: Vec<f64>,
}

pub(super) fn motion(
    r: &Request,
    model: &Model,
    inputs: &[usize],
    values: &[f64],
    o: &Options,
) -> Result<Motion, Failure> {
    let order = model.inputs();
    let zeros = vec![0.0; inputs.len()];
    let mut given = Vec::new();
    for (flag, list) in [("--rates", o.rates), ("--accels", o.accels)] {
        let list = if list.is_empty() { &zeros } else { list };
        let v = input_values(r, model, inputs, flag, list)?;
        // In the model's input order.
        given.push(
            order
                .iter()
                .map(|j| inputs.iter().position(|k| k == j).map_or(0.0, |k| v[k]))
                .collect::<Vec<f64>>(),
        );
    }
    let input_accels = given.pop().unwrap_or_default();
    let input_rates = given.pop().unwrap_or_default();
    if o.rates.is_empty() && o.accels.is_empty() {
        return Ok(Motion {
            given: false,
            input_rates,
            input_accels,
            rates: vec![0.0; values.len()],
            accels: vec![0.0; values.len()],
        });
    }
    let a = pkm_runtime::velocity::accelerations(model, values, &input_rates, &input_accels).map_err(|e| {
        Failure::new(
            Kind::Unreachable,
            format!("the inputs' rates and accelerations give no motion at the reference: {e}"),
        )
    })?;
    Ok(Motion {
        given: true,
        input_rates,
        input_accels,
        rates: a.velocities.rates,
        accels: a.rates,
    })
}

/// The actuators' forces (pkm's units, in the order of `inputs`) at
/// `values` in the reference's motion (at rest: the forces that hold it)
/// under gravity and the loads of `loading` (Newton–Euler takes and gives
/// them in the model's input order).
pub(super) fn holding(
    model: &Model,
    loading: &Loading,
    skcs: &[pkm_runtime::newton_euler::SkcParts],
    values: &[f64],
    inputs: &[usize],
    motion: &Motion,
) -> Result<Held, String> {
    let order = model.inputs();
    let r = pkm_runtime::newton_euler::inverse_dynamics(
        model,
        loading,
        skcs,
        values,
        &motion.input_rates,
        &motion.input_accels,
    )
    .map_err(|e| e.to_string())?;
    Ok(Held {
        forces: inputs
            .iter()
            .map(|j| order.iter().position(|k| k == j).map_or(f64::NAN, |k| r.actuators[k]))
            .collect(),
        conditioning: r.conditioning.iter().copied().fold(1.0, f64::min),
    })
}

/// The actuators' forces of [`holding`] and the least conditioning of an
/// SKC's force equations there (1 regular, 0 at a change point).
pub(super) struct Held {
    pub(super) forces: Vec<f64>,
    pub(super) conditioning: f64,
}
