//! Ticks: their values over a range ([`nice_ticks`]) and their labels
//! ([`tick`], [`tick_within`]), never `-0`.

/// Tick values over `lo ..= hi`: about five, at 1, 2 or 5 times a power of ten.
pub(super) fn nice_ticks(lo: f64, hi: f64) -> Vec<f64> {
    let span = hi - lo;
    if !(span > 0.0 && span.is_finite()) {
        return vec![lo];
    }
    let raw = span / 5.0;
    let power = 10f64.powf(raw.log10().floor());
    let step = [1.0, 2.0, 5.0, 10.0]
        .iter()
        .map(|m| m * power)
        .find(|s| span / s <= 6.0)
        .unwrap_or(10.0 * power);
    let first = (lo / step).ceil() as i64;
    let last = (hi / step).floor() as i64;
    (first..=last).map(|k| k as f64 * step).collect()
}

/// `v` as 0 when it is within rounding (10⁻⁹ of `span`) of it.
pub(super) fn snap(v: f64, span: f64) -> f64 {
    if v.abs() <= 1e-9 * span.abs() {
        0.0
    } else {
        v
    }
}

/// A tick label: three significant digits, a power of ten for large or
/// small values, never `-0`.
///
/// ```
/// assert_eq!(pkm_cli::plots::tick(-0.0), "0");
/// assert_eq!(pkm_cli::plots::tick(0.25), "0.25");
/// assert_eq!(pkm_cli::plots::tick(12_500_000.0), "1.25e7");
/// ```
pub fn tick(v: f64) -> String {
    tick_digits(v, 3)
}

/// A tick label on an axis spanning `span`: as [`tick`], with as many more
/// significant digits as it takes to read a hundredth of the span, so
/// that ticks a tenth of it apart read differently (a colour bar over a
/// narrow range).
///
/// ```
/// assert_eq!(pkm_cli::plots::tick_within(19_100.0, 1.0e4), "1.91e4");
/// assert_eq!(pkm_cli::plots::tick_within(19_103.5, 5.0), "19103.5");
/// ```
pub fn tick_within(v: f64, span: f64) -> String {
    let extra = if v != 0.0 && span > 0.0 && span.is_finite() {
        ((v.abs() / (0.01 * span)).log10().floor() as i32 - 2).clamp(0, 12) as usize
    } else {
        0
    };
    tick_digits(v, 3 + extra)
}

/// `v` to `significant` digits, fixed between 10⁻³ and 10⁴ (further while
/// the digits ask for it), else with a power of ten; no trailing zeros.
fn tick_digits(v: f64, significant: usize) -> String {
    if v == 0.0 || !v.is_finite() {
        return if v.is_finite() { "0".into() } else { v.to_string() };
    }
    let a = v.abs();
    let magnitude = a.log10().floor() as i32;
    let fixed_up_to = 4.max(significant as i32);
    let text = if (-3..fixed_up_to).contains(&magnitude) {
        let digits = (significant as i32 - 1 - magnitude).max(0) as usize;
        format!("{v:.digits$}")
    } else {
        let digits = significant - 1;
        format!("{v:.digits$e}")
    };
    // Trailing zeros of the mantissa go.
    let (mantissa, exponent) = text.split_once('e').map_or((text.as_str(), ""), |(m, e)| (m, e));
    let mantissa = if mantissa.contains('.') {
        mantissa.trim_end_matches('0').trim_end_matches('.')
    } else {
        mantissa
    };
    let mantissa = if mantissa == "-0" { "0" } else { mantissa };
    if exponent.is_empty() {
        mantissa.to_string()
    } else {
        format!("{mantissa}e{exponent}")
    }
}
