//! The run-time half of generated inverse dynamics: the tokens that fill
//! each SKC's fixed-size matrix on the stack, solve it (inverse, reduced
//! minimum norm, or the whole system's SVD), check every link's balance and
//! read each joint's reaction and each actuator's force out of the
//! solutions. The traced half (what the entries are) is `super`.

use super::{Balance, Direction, Reduction, Skc, Spin, Term, Traced};
use crate::emit::{lit, Emit};
use proc_macro2::TokenStream;
use quote::{format_ident, quote};

/// The generated functions: the terms (straight-line, verified like the
/// forward solution) and `inverse_dynamics`, which solves the SKCs.
pub(in crate::codegen) fn functions(
    ident: &proc_macro2::Ident,
    emit: &Emit,
    d: &Direction,
    t: &Traced,
    given_sig: &TokenStream,
    finite: &TokenStream,
    check_of: &dyn Fn(&[TokenStream]) -> TokenStream,
) -> TokenStream {
    let n_terms = t.terms.len();
    let mut roots = t.terms.clone();
    roots.extend(&d.given.residual);
    roots.push(d.given.extent);
    let (lets, exprs) = emit.straight(&roots, &emit.needed_guards(&roots, &d.given.guards, &d.given.waivable));
    let (values, rest) = exprs.split_at(n_terms);
    let check = check_of(rest);
    let (n_given, n_choices) = (d.plan.n_inputs, d.plan.branches);
    let rt = quote! { ::pkm::runtime::__private };
    let body_checks = t.bodies.iter().map(|(name, mass, moments)| {
        let (mass, moments) = (term(mass), moments.iter().map(term));
        quote! {
            if let ::core::option::Option::Some(problem) = #rt::mass_properties::body_problem(#mass, &[#(#moments),*]) {
                return ::core::result::Result::Err(#rt::newton_euler::DynamicsError::MassProperties { body: ::std::borrow::Cow::Borrowed(#name), problem });
            }
        }
    });
    let spin_checks = t.spins.iter().map(|spin| {
        let v3 = |x: &[Term; 3]| {
            let [a, b, c] = x.each_ref().map(term);
            quote! { &#rt::nalgebra::Vector3::new(#a, #b, #c) }
        };
        let (name, call) = match spin {
            Spin::Body(name, point, axis, centroid, inertia) => {
                let (point, axis, centroid) = (v3(point), v3(axis), v3(centroid));
                let inertia = inertia.iter().map(term);
                (
                    name,
                    quote! { #rt::mass_properties::idle_spin_problem(#centroid, &#rt::nalgebra::Matrix3::new(#(#inertia),*), #point, #axis, size) },
                )
            }
            Spin::Load(name, point, axis, at, moment) => {
                let (point, axis, at, moment) = (v3(point), v3(axis), v3(at), v3(moment));
                (
                    name,
                    quote! { #rt::mass_properties::idle_spin_load_problem(#at, #moment, #point, #axis, size) },
                )
            }
        };
        quote! {
            if let ::core::option::Option::Some(problem) = #call {
                return ::core::result::Result::Err(#rt::newton_euler::DynamicsError::MassProperties { body: ::std::borrow::Cow::Borrowed(#name), problem });
            }
        }
    });
    // The SKCs in reverse order.
    let solves = t.skcs.iter().enumerate().rev().map(|(k, s)| solve_skc(t, k, s));
    let balances = t.balances.iter().map(|b| balance_check(t, b));
    let reactions = (0..t.points.len()).map(|j| reaction(t, j));
    let actuators = t.actuators.iter().map(|(j, xi, bars)| actuator(t, *j, xi, bars));
    let size = term(&t.size);
    let n_skcs = t.skcs.len();
    let result = format_ident!("{}Dynamics", ident);
    quote! {
        /// The terms of the inverse dynamics for one branch: the forward
        /// solution's link motions turned into every SKC's reaction
        /// equations, verified like the forward solution.
        #[allow(clippy::type_complexity)]
        fn inverse_dynamics_terms(
            &self,
            #given_sig,
            rates: &[f64; #n_given],
            accelerations: &[f64; #n_given],
        ) -> ::core::result::Result<[f64; #n_terms], #rt::solution::SolveError> {
            let _ = (&signs, rates, accelerations);
            #finite
            #lets
            #check
            ::core::result::Result::Ok([#(#values),*])
        }

        /// Inverse dynamics for one branch by Newton–Euler over the ordered
        /// SKCs: the actuators' forces (N) or torques (N·L) that drive the
        /// mechanism at the inputs `given` with `rates` and `accelerations`
        /// against gravity and the declared loads, and every joint's
        /// reaction. The SKCs are solved in reverse order, each from its own
        /// links' balances; where statics leaves reactions undetermined
        /// they are the minimum-norm ones. Verified: every link balances.
        pub fn inverse_dynamics(
            &self,
            given: &[f64; #n_given],
            signs: [#rt::primitives::Sign; #n_choices],
            rates: &[f64; #n_given],
            accelerations: &[f64; #n_given],
        ) -> ::core::result::Result<#result, #rt::newton_euler::DynamicsError> {
            if !rates.iter().chain(accelerations.iter()).all(|v| v.is_finite()) {
                return ::core::result::Result::Err(#rt::newton_euler::DynamicsError::NotFinite);
            }
            let t = self
                .inverse_dynamics_terms(given, signs, rates, accelerations)
                .map_err(#rt::newton_euler::DynamicsError::Position)?;
            #(#body_checks)*
            if !t.iter().all(|v| v.is_finite()) {
                return ::core::result::Result::Err(#rt::newton_euler::DynamicsError::NotFinite);
            }
            let size = #size;
            #(#spin_checks)*
            // At rest the forces lose digits more slowly than in motion.
            let moving = rates.iter().chain(accelerations.iter()).any(|v| *v != 0.0);
            let mut conditioning = [1.0f64; #n_skcs];
            let mut undetermined = [0usize; #n_skcs];
            #(#solves)*
            let mut balance = 0.0f64;
            #(#balances)*
            if balance.is_nan() || balance > #rt::newton_euler::UNBALANCED {
                return ::core::result::Result::Err(#rt::newton_euler::DynamicsError::Unbalanced { balance });
            }
            ::core::result::Result::Ok(#result {
                actuators: [#(#actuators),*],
                joints: [#(#reactions),*],
                conditioning,
                undetermined,
                balance,
            })
        }
    }
}

/// `sign · x` for a sign ±1.
fn signed(sign: f64, x: TokenStream) -> TokenStream {
    if sign < 0.0 {
        quote! { -#x }
    } else {
        x
    }
}

/// A term as the generated function reads it.
fn term(x: &Term) -> TokenStream {
    match x {
        Term::Const(c) => lit(*c),
        Term::At(i) => quote! { t[#i] },
    }
}

fn is_zero(x: &Term) -> bool {
    matches!(x, Term::Const(z) if *z == 0.0)
}

/// The name of SKC `k`'s solution.
fn x_of(k: usize) -> proc_macro2::Ident {
    format_ident!("x{}", k)
}

/// Component `c` of a solution `x` in N (or N·L: a moment was solved over the size).
fn in_units(t: &Traced, x: TokenStream, c: usize) -> TokenStream {
    if c >= t.moments_from {
        quote! { #x * size }
    } else {
        x
    }
}

/// SKC `k`'s matrix and right-hand side filled in, decomposed and solved
/// on the stack: `let xk = …;`.
fn solve_skc(t: &Traced, k: usize, s: &Skc) -> TokenStream {
    let rt = quote! { ::pkm::runtime::__private };
    let n = s.rows.max(s.joints.len() * t.d);
    let x = x_of(k);
    let entries = s.entries.iter().filter(|e| !is_zero(&e.2)).map(|(r, c, v)| {
        let v = term(v);
        quote! { a[(#r, #c)] = #v; }
    });
    let rhs = s.rhs.iter().enumerate().filter(|(_, v)| !is_zero(v)).map(|(r, v)| {
        let v = term(v);
        quote! { b[#r] = #v; }
    });
    // b −= sign·x for the reactions later SKCs found.
    let known = s.known.iter().map(|&(r, j, c, sign)| {
        let (owner, at) = t.place[j];
        let (xk, col) = (x_of(owner), at + c);
        if sign < 0.0 {
            quote! { b[#r] += #xk[#col]; }
        } else {
            quote! { b[#r] -= #xk[#col]; }
        }
    });
    let n_act = s.actuated.len();
    let actuated = if n_act == 0 {
        quote! { let actuated = [0.0f64; 0]; }
    } else {
        let len = n_act * n;
        let fill = s.actuated.iter().enumerate().flat_map(|(i, row)| {
            row.iter().filter(|(_, v)| !is_zero(v)).map(move |(c, v)| {
                let (at, v) = (i * n + c, term(v));
                quote! { actuated[#at] = #v; }
            })
        });
        quote! {
            let mut actuated = [0.0f64; #len];
            #(#fill)*
        }
    };
    let joints = &s.joints;
    let undetermined = s.undetermined;
    let unknowns = s.joints.len() * t.d;
    // Where the SKC reduces to its cut joints, the reduced solve has set
    // its kinematic conditioning; else the whole system's is.
    let kinematic = if s.reduction.is_some() {
        quote! {}
    } else {
        quote! {
            #rt::force_system::near_change_point(solved.conditioning, moving, #k, &[#(#joints),*])?;
            conditioning[#k] = solved.conditioning;
        }
    };
    let full = quote! {
        let mut a = #rt::nalgebra::SMatrix::<f64, #n, #n>::zeros();
        #(#entries)*
        let svd = a.svd(true, true);
        let (::core::option::Option::Some(u), ::core::option::Option::Some(v_t)) = (svd.u.as_ref(), svd.v_t.as_ref()) else {
            return ::core::result::Result::Err(#rt::newton_euler::DynamicsError::NotFinite);
        };
        let decomposition = #rt::force_system::Decomposition {
            n: #n,
            singular_values: svd.singular_values.as_slice(),
            u: u.as_slice(),
            v_t: v_t.as_slice(),
            matrix: a.as_slice(),
        };
        let mut x = [0.0f64; #n];
        let solved = #rt::force_system::min_norm(&decomposition, b.as_slice(), #k, &[#(#joints),*], #unknowns, #undetermined, &actuated, size, &mut x)?;
        #kinematic
        undetermined[#k] = solved.undetermined;
        x
    };
    let reduced = s.reduction.as_ref().map(|r| reduced_solve(t, k, s, r));
    let body = match reduced {
        Some(reduced) => quote! {
            'solve: {
                let mut b = #rt::nalgebra::SVector::<f64, #n>::zeros();
                #(#rhs)*
                #(#known)*
                #actuated
                #reduced
                #full
            }
        },
        None => quote! {
            {
                let mut b = #rt::nalgebra::SVector::<f64, #n>::zeros();
                #(#rhs)*
                #(#known)*
                #actuated
                #full
            }
        },
    };
    quote! {
        let #x: [f64; #n] = #body;
    }
}

/// SKC `k`'s reduced solve ([`Reduction`]): `x0` from the link rows'
/// right-hand sides in `b`, `q` and `G`, then `y` by `G⁻¹ q` (a determined
/// SKC) or the minimum-norm solve of the reduction; `break 'solve x` with
/// the reactions, or on to the whole system near a change point.
fn reduced_solve(t: &Traced, k: usize, s: &Skc, r: &Reduction) -> TokenStream {
    let rt = quote! { ::pkm::runtime::__private };
    let d = t.d;
    let n = s.joints.len() * d;
    let m = r.cuts.len() * d;
    let link_rows = s.rows - r.passive.len();
    let joints = &s.joints;
    // x0: a tree joint's subtree sums.
    let x0 = r
        .tree
        .iter()
        .enumerate()
        .filter_map(|(i, t)| t.as_ref().map(|ts| (i, ts)))
        .flat_map(|(i, (sign, subtree))| {
            (0..d).map(move |c| {
                let sum = subtree.iter().map(|l| {
                    let row = l * d + c;
                    quote! { b[#row] }
                });
                let at = i * d + c;
                let sum = quote! { (#(#sum)+*) };
                let value = signed(*sign, sum);
                quote! { x0[#at] = #value; }
            })
        });
    // q = the passive rows' right-hand sides − P x0.
    let q = r.passive.iter().enumerate().map(|(row, (i, p, _))| {
        let from = link_rows + row;
        let terms = p.iter().enumerate().filter(|(_, v)| !is_zero(v)).map(|(cc, v)| {
            let (v, at) = (term(v), i * d + cc);
            quote! { #v * x0[#at] }
        });
        quote! { q[#row] = b[#from] #(- #terms)*; }
    });
    let g = r.g.iter().filter(|e| !is_zero(&e.2)).map(|(row, col, v)| {
        let v = term(v);
        quote! { g[(#row, #col)] = #v; }
    });
    let prelude = quote! {
        let mut x0 = [0.0f64; #n];
        #(#x0)*
        let mut q = #rt::nalgebra::SVector::<f64, #m>::zeros();
        #(#q)*
        let mut g = #rt::nalgebra::SMatrix::<f64, #m, #m>::zeros();
        #(#g)*
        // Each passive row as a direction: the kinematic conditioning's.
        #rt::force_system::unit_rows(g.as_mut_slice(), #m, q.as_mut_slice());
    };
    if s.undetermined == 0 && r.passive.len() == m {
        // x = x0 + C y.
        let add = c_times(s, r, d, quote! { += });
        quote! {
            #prelude
            // The bound from the inverse where it is above the least, else σ_m/σ_1.
            let inverse = g.try_inverse();
            let bound = inverse.as_ref().map_or(0.0, |inverse| {
                #rt::force_system::conditioning_bound(g.as_slice(), inverse.as_slice())
            });
            let kinematic = #rt::force_system::conditioning_from_bound(bound, || {
                #rt::force_system::conditioning_of(g.singular_values().as_slice(), #m)
            });
            conditioning[#k] = kinematic;
            #rt::force_system::near_change_point(kinematic, moving, #k, &[#(#joints),*])?;
            if let (true, ::core::option::Option::Some(inverse)) = (bound > #rt::force_system::LU_TRUSTED, inverse) {
                let y = inverse * q;
                let _ = &actuated;
                let mut x = x0;
                #(#add)*
                break 'solve x;
            }
        }
    } else {
        // C y, written out: C is block-diagonal in the components.
        let set = c_times(s, r, d, quote! { = });
        let undetermined = s.undetermined;
        let rank = m.saturating_sub(undetermined);
        let null = undetermined.min(m);
        let passive = r.passive.len();
        if passive > 0 && passive == rank {
            // The passive rows independent (as the topology has them): the
            // row space of G by Householder, its null space with it.
            let (transposed, gram) = (c_transposed(s, r, d), c_gram(r, d));
            return quote! {
                #prelude
                let rows: [[f64; #m]; #passive] = ::core::array::from_fn(|i| ::core::array::from_fn(|j| g[(i, j)]));
                let (basis, r) = #rt::force_system::row_space::<#m, #passive>(&rows);
                // The bound from R's inverse where it is above the least, else σ_P/σ_1.
                let bound = #rt::force_system::triangular_bound(&r);
                let kinematic = #rt::force_system::conditioning_from_bound(bound, || {
                    #rt::force_system::conditioning_of(r.singular_values().as_slice(), #rank)
                });
                conditioning[#k] = kinematic;
                #rt::force_system::near_change_point(kinematic, moving, #k, &[#(#joints),*])?;
                let c = |y: &[f64; #m]| -> [f64; #n] {
                    let mut x = [0.0f64; #n];
                    #(#set)*
                    x
                };
                // Cᵀ and CᵀC: the null directions are made orthonormal in y's space.
                let ct = |x: &[f64; #n]| -> [f64; #m] {
                    let mut y = [0.0f64; #m];
                    #(#transposed)*
                    y
                };
                let gram = |v: &[f64; #m]| -> [f64; #m] {
                    let mut y = [0.0f64; #m];
                    #(#gram)*
                    y
                };
                let mut x = [0.0f64; #n];
                if let ::core::option::Option::Some(solved) = #rt::force_system::reduced_min_norm_qr::<#n, #m, #passive, #null>(&basis, &r, kinematic, &q.into(), &x0, c, ct, gram, #k, &actuated, size, &mut x)? {
                    undetermined[#k] = solved.undetermined;
                    break 'solve x;
                }
            };
        }
        quote! {
            #prelude
            let svd = g.svd(true, true);
            let kinematic = #rt::force_system::conditioning_of(svd.singular_values.as_slice(), #rank);
            conditioning[#k] = kinematic;
            #rt::force_system::near_change_point(kinematic, moving, #k, &[#(#joints),*])?;
            if let (::core::option::Option::Some(u), ::core::option::Option::Some(v_t)) = (svd.u.as_ref(), svd.v_t.as_ref()) {
                let decomposition = #rt::force_system::Decomposition {
                    n: #m,
                    singular_values: svd.singular_values.as_slice(),
                    u: u.as_slice(),
                    v_t: v_t.as_slice(),
                    matrix: g.as_slice(),
                };
                let c = |y: &[f64; #m]| -> [f64; #n] {
                    let mut x = [0.0f64; #n];
                    #(#set)*
                    x
                };
                let mut x = [0.0f64; #n];
                if let ::core::option::Option::Some(solved) = #rt::force_system::reduced_min_norm::<#n, #m, #null>(&decomposition, &q.into(), &x0, c, #k, #undetermined, &actuated, size, &mut x)? {
                    undetermined[#k] = solved.undetermined;
                    break 'solve x;
                }
            }
        }
    }
}

/// `x[i] op (C y)[i]` for each reaction component `i` that a cut joint's
/// reaction reaches: `C` is ±1 per joint and cut joint, the same for each
/// of the `d` components.
fn c_times(s: &Skc, r: &Reduction, d: usize, op: TokenStream) -> Vec<TokenStream> {
    (0..s.joints.len())
        .flat_map(|i| {
            let op = op.clone();
            (0..d).filter_map(move |c| {
                let at = i * d + c;
                let parts: Vec<TokenStream> = r.coef[i]
                    .iter()
                    .enumerate()
                    .filter(|(_, v)| **v != 0.0)
                    .map(|(kk, v)| {
                        signed(*v, {
                            let col = kk * d + c;
                            quote! { y[#col] }
                        })
                    })
                    .collect();
                (!parts.is_empty()).then(|| quote! { x[#at] #op #(#parts)+*; })
            })
        })
        .collect()
}

/// `y[j] = (Cᵀ x)[j]` for each of the cut joints' components `j` (`C` as
/// in [`c_times`]).
fn c_transposed(s: &Skc, r: &Reduction, d: usize) -> Vec<TokenStream> {
    let cuts = r.cuts.len();
    (0..cuts * d)
        .filter_map(|col| {
            let (kk, c) = (col / d, col % d);
            let parts: Vec<TokenStream> = (0..s.joints.len())
                .filter(|&i| r.coef[i][kk] != 0.0)
                .map(|i| {
                    let at = i * d + c;
                    signed(r.coef[i][kk], quote! { x[#at] })
                })
                .collect();
            (!parts.is_empty()).then(|| quote! { y[#col] = #(#parts)+*; })
        })
        .collect()
}

/// `y[j] = (CᵀC v)[j]`: `CᵀC` is `W ⊗ I_d` with `W` the cut joints'
/// integer Gram matrix, `W[k][l] = Σ_i C[i][k] C[i][l]` over the joints.
fn c_gram(r: &Reduction, d: usize) -> Vec<TokenStream> {
    let cuts = r.cuts.len();
    let w = |k: usize, l: usize| r.coef.iter().map(|row| row[k] * row[l]).sum::<f64>();
    (0..cuts * d)
        .filter_map(|col| {
            let (k, c) = (col / d, col % d);
            let parts: Vec<TokenStream> = (0..cuts)
                .filter(|&l| w(k, l) != 0.0)
                .map(|l| {
                    let at = l * d + c;
                    match w(k, l) {
                        1.0 => quote! { v[#at] },
                        -1.0 => quote! { -v[#at] },
                        f => {
                            let f = lit(f);
                            quote! { #f * v[#at] }
                        }
                    }
                })
                .collect();
            (!parts.is_empty()).then(|| quote! { y[#col] = #(#parts)+*; })
        })
        .collect()
}

/// One link's balance: the demand against its joints' reactions, folded
/// into `balance`.
fn balance_check(t: &Traced, b: &Balance) -> TokenStream {
    let components = (0..t.d).map(|c| {
        let reactions = b.on.iter().map(|&(j, sign)| {
            let (k, at) = t.place[j];
            let (xk, col) = (x_of(k), at + c);
            signed(sign, quote! { #xk[#col] })
        });
        let need = match &b.need[c] {
            Term::Const(v) => lit(-v),
            at => {
                let v = term(at);
                quote! { -#v }
            }
        };
        quote! { [#need, #(#reactions),*] }
    });
    quote! {
        balance = balance.max(::pkm::runtime::__private::force_system::relative_residual(&[#(#components),*]));
    }
}

/// Joint `j`'s reaction at its point, in N and N·L.
fn reaction(t: &Traced, j: usize) -> TokenStream {
    let (k, at) = t.place[j];
    let xk = x_of(k);
    let w: Vec<TokenStream> = (0..t.d)
        .map(|c| {
            let col = at + c;
            in_units(t, quote! { #xk[#col] }, c)
        })
        .collect();
    let (f, mo) = if t.d == 3 {
        let (fx, fy, mz) = (&w[0], &w[1], &w[2]);
        (quote! { [#fx, #fy, 0.0] }, quote! { [0.0, 0.0, #mz] })
    } else {
        let (fx, fy, fz, mx, my, mz) = (&w[0], &w[1], &w[2], &w[3], &w[4], &w[5]);
        (quote! { [#fx, #fy, #fz] }, quote! { [#mx, #my, #mz] })
    };
    let p = t.points[j].iter().map(term);
    let metres = lit(t.metres);
    quote! {
        {
            let (f, m, p): ([f64; 3], [f64; 3], [f64; 3]) = (#f, #mo, [#(#p),*]);
            // The moment about the joint's point: m_o − p × f.
            let at = [
                m[0] - (p[1] * f[2] - p[2] * f[1]),
                m[1] - (p[2] * f[0] - p[0] * f[2]),
                m[2] - (p[0] * f[1] - p[1] * f[0]),
            ];
            ::pkm::runtime::__private::newton_euler::JointReaction {
                force: [f[0] * #metres, f[1] * #metres, f[2] * #metres],
                moment: [at[0] * #metres, at[1] * #metres, at[2] * #metres],
            }
        }
    }
}

/// An actuator's force: its joint's reaction's power along its twist, in N or N·L.
fn actuator(t: &Traced, j: usize, xi: &[Term], bars: &Term) -> TokenStream {
    let (k, at) = t.place[j];
    let xk = x_of(k);
    let sum: Vec<TokenStream> = (0..t.d)
        .filter(|&c| !is_zero(&xi[c]))
        .map(|c| {
            let col = at + c;
            let x = in_units(t, quote! { #xk[#col] }, c);
            match xi[c] {
                Term::Const(1.0) => x,
                Term::Const(-1.0) => quote! { -(#x) },
                other => {
                    let k = term(&other);
                    quote! { #k * (#x) }
                }
            }
        })
        .collect();
    let metres = lit(t.metres);
    let bars = (!is_zero(bars)).then(|| {
        let b = term(bars);
        quote! { + #b }
    });
    if sum.is_empty() {
        quote! { (0.0 #bars) * #metres }
    } else {
        quote! { (#(#sum)+* #bars) * #metres }
    }
}

/// `NameDynamics`, what `inverse_dynamics` returns, and `Name::inverse_dynamics`.
pub(in crate::codegen) fn items(
    ident: &proc_macro2::Ident,
    vis: &syn::Visibility,
    d: &Direction,
    t: &Traced,
) -> TokenStream {
    let rt = quote! { ::pkm::runtime::__private };
    let result = format_ident!("{}Dynamics", ident);
    let params_ty = format_ident!("{}Params", ident);
    let (n_act, n_joints, n_skcs) = (t.actuators.len(), t.points.len(), t.skcs.len());
    let (n_given, n_choices) = (d.plan.n_inputs, d.plan.branches);
    let doc = format!(" What [`{ident}Prepared::inverse_dynamics`] finds.");
    let fn_doc = format!(" Inverse dynamics for one branch ([`{ident}Prepared::inverse_dynamics`]).");
    quote! {
        #[doc = #doc]
        #[derive(Debug, Clone, Copy, PartialEq)]
        #vis struct #result {
            /// The actuators' forces (N) or torques (N·L), in `INPUTS` order.
            pub actuators: [f64; #n_act],
            /// Every joint's reaction (`JOINTS` order): the force and the
            /// moment about its point that its first link exerts on its
            /// second, base axes (N and N·L).
            pub joints: [#rt::newton_euler::JointReaction; #n_joints],
            /// Per SKC (position solution's order), its kinematic
            /// conditioning, near 0 at a change point: σ_r/σ_1 of its
            /// passive rows on its cut joints' reactions (the transpose of
            /// its passive velocity equations; where a lower bound of it,
            /// 1/(‖G‖_F ‖G⁻¹‖_F) for a determined SKC or 1/(‖R‖_F ‖R⁻¹‖_F)
            /// of its independent passive rows' triangular factor for an
            /// overconstrained one, is 6.06e-4 or more, that bound), as
            /// the runtime's Newton–Euler reports it; below
            /// 6.06e-4 in motion (1.5e-5 at rest) the answer is
            /// `DynamicsError::NearChangePoint` instead.
            pub conditioning: [f64; #n_skcs],
            /// Per SKC, the reaction components statics leaves undetermined.
            pub undetermined: [usize; #n_skcs],
            /// The largest residual of a link's balance, relative to its largest term.
            pub balance: f64,
        }

        #[automatically_derived]
        impl #ident {
            #[doc = #fn_doc]
            /// Prepares the solver and solves: to solve often at the same
            /// parameters, prepare once (`prepare`) and call its `inverse_dynamics`.
            pub fn inverse_dynamics(
                params: &#params_ty,
                q: &[f64; #n_given],
                signs: [#rt::primitives::Sign; #n_choices],
                rates: &[f64; #n_given],
                accelerations: &[f64; #n_given],
            ) -> ::core::result::Result<#result, #rt::newton_euler::DynamicsError> {
                Self::prepare(params).inverse_dynamics(q, signs, rates, accelerations)
            }
        }
    }
}
