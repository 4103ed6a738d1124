//! The declared outputs' rates ([`output_rates`]), the velocity maps
//! between inputs and outputs ([`jacobians`]) and which singularity a
//! configuration is at ([`Singularity`], Gosselin and Angeles).

use super::twist::Twist;
use super::{loops, refined_solve, relative_of, Loops, VelocityError, SINGULAR};
use crate::model::{JointType, Model};
use crate::newton::Output;
use nalgebra::{DMatrix, DVector, Dyn, Isometry3, Vector3, SVD};

/// The rates of the declared outputs for a link twist map.
pub fn output_rates(
    model: &Model,
    poses: &[Isometry3<f64>],
    outputs: &[Output],
    rates: &[f64],
    twists: &[Twist],
) -> Vec<f64> {
    let (offsets, _) = model.value_offsets();
    let mut out = Vec::new();
    for o in outputs {
        let (link, local, about) = match *o {
            Output::Pose { link, local, about } => (link, local, about),
            Output::Point { link, local } => (link, local, None),
            Output::Joint(j) => {
                out.push(rates[offsets[j]]);
                continue;
            }
            Output::Parts { link, local, parts } => {
                let p = poses[link].transform_point(&local.into()).coords;
                let v = twists[link].at(&p);
                let w = angle_rates(&poses[link].rotation, &twists[link].w);
                let six = [v.x, v.y, v.z, w[0], w[1], w[2]];
                out.extend(parts.given().map(|i| six[i]));
                continue;
            }
        };
        let p = poses[link].transform_point(&local.into()).coords;
        let v = twists[link].at(&p);
        out.extend_from_slice(if model.planar { &v.as_slice()[..2] } else { v.as_slice() });
        if let Some(k) = about {
            out.push(Vector3::from(k).normalize().dot(&twists[link].w));
        }
    }
    out
}

/// The rates `[ṙx, ṙy, ṙz]` of the angles of `R = R_z(rz)·R_y(ry)·R_x(rx)`
/// for the angular velocity `w` (world frame): `w = ṙz·e_z + ṙy·R_z·e_y +
/// ṙx·R_z·R_y·e_x`, so `ṙx = (w_x cos rz + w_y sin rz)/cos ry`,
/// `ṙy = −w_x sin rz + w_y cos rz`, `ṙz = w_z + ṙx sin ry` (infinite at
/// `ry = ±π/2`, where the angles lose a freedom).
pub fn angle_rates(rotation: &nalgebra::UnitQuaternion<f64>, w: &Vector3<f64>) -> [f64; 3] {
    let (_, ry, rz) = rotation.euler_angles();
    let (sz, cz) = rz.sin_cos();
    let rx_rate = (w.x * cz + w.y * sz) / ry.cos();
    [rx_rate, -w.x * sz + w.y * cz, w.z + rx_rate * ry.sin()]
}

/// Which singularity a configuration is at (Gosselin and Angeles).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Singularity {
    /// Neither.
    None,
    /// Input (inverse): the actuators can move while the outputs stay
    /// (`det J_i = 0`).
    Input,
    /// Output (forward): the outputs can move with the actuators held
    /// (`det J_o = 0`).
    Output,
    /// Both at once.
    Combined,
}

/// The velocity maps at one configuration and how far it is from each
/// singularity.
#[derive(Debug, Clone)]
pub struct Jacobians {
    /// Output rates per unit input rate (rows: outputs, columns: inputs);
    /// `None` at an output singularity.
    pub forward: Option<DMatrix<f64>>,
    /// Input rates per unit output rate (rows: inputs, columns: outputs),
    /// the inverse velocity map; `None` at an input singularity.
    pub inverse: Option<DMatrix<f64>>,
    /// The loop equations' passive columns, σ_min/σ_max (lengths scaled
    /// by the mechanism's size): 0 at an output singularity.
    pub output_sigma: f64,
    /// The loop and output equations over every rate, σ_min/σ_max: 0 when
    /// some motion leaves the outputs still (an input singularity).
    pub input_sigma: f64,
    /// The classification at the threshold [`SINGULAR`].
    pub singularity: Singularity,
}

/// The rows of the outputs' rates, one column per joint rate.
fn output_matrix(model: &Model, l: &Loops, outputs: &[Output]) -> DMatrix<f64> {
    let n = l.a.ncols();
    let mut columns = Vec::with_capacity(n);
    for i in 0..n {
        let mut e = vec![0.0; n];
        e[i] = 1.0;
        let twists: Vec<Twist> = (0..model.links.len()).map(|k| l.link_twist(k, &e)).collect();
        columns.push(output_rates(model, &l.poses, outputs, &e, &twists));
    }
    let rows = columns.first().map_or(0, Vec::len);
    DMatrix::from_fn(rows, n, |r, c| columns[c][r])
}

/// The velocity maps and singularity measures at `values`.
pub fn jacobians(model: &Model, values: &[f64], outputs: &[Output]) -> Result<Jacobians, VelocityError> {
    let l = loops(model, values)?;
    let scale = crate::kinematics::model_scale(model);
    let (passive, output_sigma) = l.passive_svd(scale);
    let c = output_matrix(model, &l, outputs);
    // Loop rows and output rows over every rate, lengths in units of the size.
    let all: Vec<usize> = (0..l.a.ncols()).collect();
    let a = l.scaled_columns(&all, scale);
    let mut stacked = DMatrix::zeros(a.nrows() + c.nrows(), a.ncols());
    stacked.rows_mut(0, a.nrows()).copy_from(&a);
    stacked.rows_mut(a.nrows(), c.nrows()).copy_from(&c);
    let angle_rows = output_angle_rows(model, outputs);
    for (r, angle) in angle_rows.iter().enumerate() {
        if !angle {
            stacked.row_mut(a.nrows() + r).scale_mut(1.0 / scale);
        }
    }
    // A slide's rate per unit of the size in the output rows too (the loop
    // rows have it from `scaled_columns`).
    for (i, &p) in l.prismatic.iter().enumerate() {
        if p {
            stacked.view_mut((a.nrows(), i), (c.nrows(), 1)).scale_mut(scale);
        }
    }
    let rows = stacked.nrows();
    let matrix = stacked.clone();
    let stacked = stacked.svd(true, true);
    let input_sigma = relative_of(&stacked.singular_values);
    let inverse = if input_sigma < SINGULAR {
        None
    } else {
        inverse_map(&l, &stacked, &matrix, rows, a.nrows(), &angle_rows, scale)
    };
    let forward = if output_sigma < SINGULAR {
        None
    } else {
        let f = l.actuated.len();
        let mut jf = DMatrix::zeros(c.nrows(), f);
        for k in 0..f {
            let mut unit = vec![0.0; f];
            unit[k] = 1.0;
            let rates = l.solve_with(
                passive.as_ref(),
                output_sigma,
                &unit,
                &DVector::zeros(l.a.nrows()),
                scale,
            )?;
            jf.set_column(k, &(&c * DVector::from_vec(rates)));
        }
        Some(jf)
    };
    let singularity = match (input_sigma < SINGULAR, output_sigma < SINGULAR) {
        (false, false) => Singularity::None,
        (true, false) => Singularity::Input,
        (false, true) => Singularity::Output,
        (true, true) => Singularity::Combined,
    };
    Ok(Jacobians {
        forward,
        inverse,
        output_sigma,
        input_sigma,
        singularity,
    })
}

/// The input rates per unit output rate: the scaled loop-and-output stack
/// (its decomposition, `rows` rows) solved for every rate with the loop rows'
/// right side zero.
fn inverse_map(
    l: &Loops,
    svd: &SVD<f64, Dyn, Dyn>,
    matrix: &DMatrix<f64>,
    rows: usize,
    loop_rows: usize,
    angle_rows: &[bool],
    scale: f64,
) -> Option<DMatrix<f64>> {
    let tolerance = 1e-13 * svd.singular_values.max();
    let outputs = rows - loop_rows;
    let mut ji = DMatrix::zeros(l.actuated.len(), outputs);
    for k in 0..outputs {
        let mut rhs = DVector::zeros(rows);
        rhs[loop_rows + k] = if angle_rows[k] { 1.0 } else { 1.0 / scale };
        let y = refined_solve(svd, matrix, &rhs, tolerance)?;
        for (r, &i) in l.actuated.iter().enumerate() {
            ji[(r, k)] = y[i] * if l.prismatic[i] { scale } else { 1.0 };
        }
    }
    Some(ji)
}

/// Which output rows are angles.
fn output_angle_rows(model: &Model, outputs: &[Output]) -> Vec<bool> {
    let point = if model.planar { 2 } else { 3 };
    outputs
        .iter()
        .flat_map(|o| match *o {
            Output::Pose { about, .. } => {
                let mut v = vec![false; point];
                if about.is_some() {
                    v.push(true);
                }
                v
            }
            Output::Point { .. } => vec![false; point],
            Output::Parts { parts, .. } => parts.given().map(|i| i >= 3).collect(),
            Output::Joint(j) => vec![model.joints[j].kind != JointType::P],
        })
        .collect()
}
