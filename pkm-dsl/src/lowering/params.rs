//! Parameter values given from outside the file (the command line's and the
//! report's `--param name=value`): checked once, here, before any model is
//! built, so that every caller refuses the same inputs with the same reasons.

use crate::topology::analysis::Analysis;
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
