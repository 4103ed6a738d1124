//! The `units { … }` block: the file's length and mass units, checked.

use super::*;
use crate::diagnostics::{Diagnostic, Diagnostics};

/// A length unit.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LengthUnit {
    /// Metre.
    M,
    /// Centimetre.
    Cm,
    /// Millimetre.
    Mm,
}
impl LengthUnit {
    /// The unit in metres.
    pub fn metres(self) -> f64 {
        match self {
            LengthUnit::M => 1.0,
            LengthUnit::Cm => 1e-2,
            LengthUnit::Mm => 1e-3,
        }
    }

    /// The unit's symbol, as the file writes it.
    pub fn symbol(self) -> &'static str {
        match self {
            LengthUnit::M => "m",
            LengthUnit::Cm => "cm",
            LengthUnit::Mm => "mm",
        }
    }
}
/// A mass unit.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum MassUnit {
    /// Kilogram.
    Kg,
    /// Gram.
    G,
}
impl MassUnit {
    /// The unit in kilograms.
    pub fn kilograms(self) -> f64 {
        match self {
            MassUnit::Kg => 1.0,
            MassUnit::G => 1e-3,
        }
    }
}
/// The file's units.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Units {
    /// Lengths (geometry, centroids, load points) and the solutions' lengths.
    pub length: LengthUnit,
    /// Masses; inertias are in mass unit · length unit².
    pub mass: MassUnit,
}
/// The one `units` block, checked.
pub(super) fn units(blocks: &[UnitsDecl], errors: &mut Diagnostics) -> Option<Units> {
    if let Some(second) = blocks.get(1) {
        errors.push(
            Diagnostic::new(second.span, "a mechanism has one `units` block")
                .label("a second one")
                .also(blocks[0].span, "the first"),
        );
    }
    let block = blocks.first()?;
    let (mut length, mut mass) = (None, None);
    for (key, unit) in &block.items {
        let (slot, parsed) = match key.text.as_str() {
            "length" => (
                &mut length,
                match unit.text.as_str() {
                    "m" => Some(UnitKind::Length(LengthUnit::M)),
                    "cm" => Some(UnitKind::Length(LengthUnit::Cm)),
                    "mm" => Some(UnitKind::Length(LengthUnit::Mm)),
                    _ => None,
                },
            ),
            "mass" => (
                &mut mass,
                match unit.text.as_str() {
                    "kg" => Some(UnitKind::Mass(MassUnit::Kg)),
                    "g" => Some(UnitKind::Mass(MassUnit::G)),
                    _ => None,
                },
            ),
            _ => {
                errors.push(
                    Diagnostic::new(key.span, format!("unknown unit `{}`", key.text))
                        .label("not a quantity")
                        .note("the units are `length` (m, cm, mm) and `mass` (kg, g); time is in s"),
                );
                continue;
            }
        };
        let Some(parsed) = parsed else {
            let choices = if key.text == "length" { "m, cm or mm" } else { "kg or g" };
            errors.push(
                Diagnostic::new(unit.span, format!("`{}` is not a unit of {}", unit.text, key.text)).label(choices),
            );
            continue;
        };
        if slot.replace((parsed, key.span)).is_some() {
            errors.push(Diagnostic::new(key.span, format!("`{}` is given twice", key.text)).label("again"));
        }
    }
    // A key written with a wrong unit is reported above, not as missing.
    let written = |k: &str| block.items.iter().any(|(key, _)| key.text == k);
    let missing: Vec<&str> = ["length", "mass"].into_iter().filter(|k| !written(k)).collect();
    if !missing.is_empty() {
        errors.push(
            Diagnostic::new(block.span, format!("`units` needs `{}`", missing.join("` and `")))
                .label("incomplete")
                .note("for example `units { length = mm; mass = kg; }`"),
        );
        return None;
    }
    match (length, mass) {
        (Some((UnitKind::Length(length), _)), Some((UnitKind::Mass(mass), _))) => Some(Units { length, mass }),
        _ => None,
    }
}
/// A parsed unit, of either quantity.
#[derive(Debug, Clone, Copy)]
pub(super) enum UnitKind {
    Length(LengthUnit),
    Mass(MassUnit),
}
