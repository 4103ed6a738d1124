//! Parameter values given from outside the file (the command line's and the
//! report's `--param name=value`): checked once, here, before any model is
//! built, so that every caller refuses the same inputs with the same reasons.

use crate::topology::analysis::Analysis;
use nalgebra::Vector3;
use pkm_runtime::model::{Model, Place};
use std::collections::HashMap;

/// Why a list of parameter overrides is refused.
#[derive(Debug, Clone, PartialEq)]
pub enum ParamError {
    /// `name` is not a declared parameter.
    Unknown {
        /// The name given.
        name: String,
        /// The declared parameters, in declaration order (empty when there are none).
        known: Vec<String>,
        /// The mechanism's name.
        mechanism: String,
    },
    /// The value of `name` is NaN or infinite.
    NotFinite {
        /// The parameter.
        name: String,
        /// Its value as given.
        value: f64,
    },
    /// `name` is given more than once (which value was meant is not known).
    Twice {
        /// The parameter.
        name: String,
    },
}

impl ParamError {
    /// The parameter the error is about.
    pub fn name(&self) -> &str {
        match self {
            ParamError::Unknown { name, .. } | ParamError::NotFinite { name, .. } | ParamError::Twice { name } => name,
        }
    }
}

impl std::fmt::Display for ParamError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            ParamError::Unknown { name, known, mechanism } if known.is_empty() => {
                write!(f, "unknown parameter `{name}`: {mechanism} has no parameters")
            }
            ParamError::Unknown { name, known, .. } => {
                write!(f, "unknown parameter `{name}`; the parameters are {}", known.join(", "))
            }
            ParamError::NotFinite { name, value } if value.is_nan() => write!(f, "parameter {name} is NaN"),
            ParamError::NotFinite { name, value } => write!(f, "parameter {name} = {value} is not finite"),
            ParamError::Twice { name } => write!(f, "parameter {name} is given twice"),
        }
    }
}

impl std::error::Error for ParamError {}

/// The overrides `given` (name, value; in the order given) by name: each a
/// declared parameter of `a`, finite, given once. The parameters not given
/// keep their values from the file (derived ones follow the overrides when
/// the model is built).
///
/// ```
/// let a = pkm_dsl::analyze_source("mechanism m { planar; base R1* ∥ R2 ∥ R3 ∥ R4 base;
///     parameters { l1 = 100; l2 = 2 * l1; } }").unwrap();
/// let ok = pkm_dsl::params::overrides(&a, &[("l1".into(), 90.0)]).unwrap();
/// assert_eq!(ok.len(), 1);
/// let twice = pkm_dsl::params::overrides(&a, &[("l1".into(), 1.0), ("l1".into(), 2.0)]);
/// assert_eq!(twice.unwrap_err().to_string(), "parameter l1 is given twice");
/// ```
pub fn overrides(a: &Analysis, given: &[(String, f64)]) -> Result<HashMap<String, f64>, ParamError> {
    let known: Vec<&str> = a.geometry.parameters.iter().map(|p| p.name.as_str()).collect();
    let mut values = HashMap::with_capacity(given.len());
    for &(ref name, value) in given {
        if !known.contains(&name.as_str()) {
            return Err(ParamError::Unknown {
                name: name.clone(),
                known: known.iter().map(|k| k.to_string()).collect(),
                mechanism: a.mechanism.name.clone(),
            });
        }
        if !value.is_finite() {
            return Err(ParamError::NotFinite {
                name: name.clone(),
                value,
            });
        }
        if values.insert(name.clone(), value).is_some() {
            return Err(ParamError::Twice { name: name.clone() });
        }
    }
    Ok(values)
}

/// Rejects an override that takes a length of the mechanism through zero.
/// Each override is applied alone to the declared dimensions (`nominal`,
/// the model at the file's values); a distance between two points of one
/// link that becomes zero, or (on a moving link) turns to point the
/// opposite way along the same line, went through zero on the way:
/// `l2 = -5` for a link declared `l2` long. Base points are positions,
/// which may change sides, so only their coincidence counts. The reason,
/// as the command line prints it.
pub fn check_lengths(a: &Analysis, nominal: &Model, values: &HashMap<String, f64>) -> Result<(), String> {
    let declared = a.geometry.nominal();
    let mut names: Vec<&String> = values.keys().collect();
    names.sort();
    for name in names {
        let v = values[name];
        // A model that does not build fails later with its own diagnostics.
        let Ok(changed) = crate::lowering::numeric::model(a, &HashMap::from([(name.clone(), v)])) else {
            continue;
        };
        for (link, link_name) in nominal.links.iter().enumerate() {
            let (before, after) = (link_points(nominal, link), link_points(&changed, link));
            for i in 0..before.len() {
                for k in i + 1..before.len().min(after.len()) {
                    let d0 = Vector3::from(before[k].1) - Vector3::from(before[i].1);
                    let d1 = Vector3::from(after[k].1) - Vector3::from(after[i].1);
                    let (n0, n1) = (d0.norm(), d1.norm());
                    if n0 == 0.0 {
                        continue;
                    }
                    let (p, q) = (before[i].0, before[k].0);
                    let at_declared = format!("at the declared {name} = {}", declared[name]);
                    if n1 <= 1e-9 * n0 {
                        return Err(format!(
                            "parameter {name} = {v} puts {p} and {q} of link {link_name} at one point \
                             (they are {n0} apart {at_declared})"
                        ));
                    }
                    if link != 0 && d0.dot(&d1) < 0.0 && d0.cross(&d1).norm() <= 1e-9 * n0 * n1 {
                        let rule = match declared[name] {
                            d if d > 0.0 => "must be positive",
                            d if d < 0.0 => "must be negative",
                            _ => "is out of range",
                        };
                        return Err(format!(
                            "parameter {name} = {v} {rule}: the distance {p}–{q} on link {link_name} \
                             ({n0} {at_declared}) would pass through zero"
                        ));
                    }
                }
            }
        }
    }
    Ok(())
}

/// The points of `link` a parameter can set the distances between: its
/// joints' places (not guide lines: any point of a line stands for it) and
/// its named points, in a fixed order.
fn link_points(model: &Model, link: usize) -> Vec<(&str, [f64; 3])> {
    let joints = model.joints.iter().flat_map(|j| {
        (0..2)
            .filter(move |&s| j.links[s] == link && !matches!(j.places[s], Place::Line { .. }))
            .map(move |s| (j.name.as_str(), j.places[s].at()))
    });
    let named = model
        .points
        .iter()
        .filter(|p| p.link == link)
        .map(|p| (p.name.as_str(), p.at));
    joints.chain(named).collect()
}

/// A joint place or named point of `model` that is not a number (a
/// parameter expression such as `sqrt(a - 100)` out of its domain), if any.
pub fn non_finite_place(model: &Model) -> Option<String> {
    let bad = |v: [f64; 3]| v.iter().any(|x| !x.is_finite());
    let joint = model.joints.iter().find_map(|j| {
        (0..2).find_map(|s| {
            let (at, axis) = (j.places[s].at(), j.places[s].axis());
            (bad(at) || bad(axis)).then(|| {
                format!(
                    "joint {}'s place on link {} is not finite ({at:?} along {axis:?})",
                    j.name, model.links[j.links[s]]
                )
            })
        })
    });
    joint.or_else(|| {
        let p = model.points.iter().find(|p| bad(p.at))?;
        Some(format!("point {} is not finite ({:?})", p.name, p.at))
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    const FOUR_BAR: &str = "mechanism four_bar { planar; base R1* ∥ R2 ∥ R3 ∥ R4 base;
        parameters { l1 = 100; l2 = 250; } }";
    const BARE: &str = "mechanism bare { planar; base R1* ∥ R2 ∥ R3 ∥ R4 base; }";

    /// The overrides of `given` on `text`: their values sorted by name, or the error's text.
    fn check(text: &str, given: &[(&str, f64)], expect: Result<&[(&str, f64)], &str>) {
        let a = crate::topology::analysis::analyze_source(text).unwrap();
        let given: Vec<(String, f64)> = given.iter().map(|(k, v)| (k.to_string(), *v)).collect();
        let got = overrides(&a, &given).map(|m| {
            let mut v: Vec<(String, f64)> = m.into_iter().collect();
            v.sort_by(|x, y| x.0.cmp(&y.0));
            v
        });
        match (got, expect) {
            (Ok(got), Ok(want)) => {
                let want: Vec<(String, f64)> = want.iter().map(|(k, v)| (k.to_string(), *v)).collect();
                assert_eq!(got, want);
            }
            (Err(e), Err(want)) => assert_eq!(e.to_string(), want),
            (got, want) => panic!("{given:?}: got {got:?}, expected {want:?}"),
        }
    }

    #[test]
    fn overrides_are_checked() {
        check(FOUR_BAR, &[], Ok(&[]));
        check(
            FOUR_BAR,
            &[("l2", 200.0), ("l1", 90.0)],
            Ok(&[("l1", 90.0), ("l2", 200.0)]),
        );
        check(
            FOUR_BAR,
            &[("zz", 1.0)],
            Err("unknown parameter `zz`; the parameters are l1, l2"),
        );
        check(
            BARE,
            &[("zz", 1.0)],
            Err("unknown parameter `zz`: bare has no parameters"),
        );
        check(FOUR_BAR, &[("l1", f64::NAN)], Err("parameter l1 is NaN"));
        check(
            FOUR_BAR,
            &[("l1", f64::NEG_INFINITY)],
            Err("parameter l1 = -inf is not finite"),
        );
        check(
            FOUR_BAR,
            &[("l1", 1.0), ("l1", 2.0)],
            Err("parameter l1 is given twice"),
        );
        // The first fault in the order given is the one named.
        check(FOUR_BAR, &[("l1", f64::NAN), ("zz", 1.0)], Err("parameter l1 is NaN"));
    }
}
